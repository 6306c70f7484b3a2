# Compiles GLSL to SPIR-V at build time and wraps each module in a C++ header
# (glslangValidator --vn), so built programs carry their shaders inside them.
find_program(GLSLANG_VALIDATOR glslangValidator REQUIRED)

# snell_shader_variable(<out-var> <file>): shaders/comp/sort_scatter.comp -> kSpvSortScatter
function(snell_shader_variable out file)
  get_filename_component(stem "${file}" NAME_WE)
  string(REPLACE "_" ";" words "${stem}")
  set(name "kSpv")
  foreach(word IN LISTS words)
    string(SUBSTRING "${word}" 0 1 first)
    string(SUBSTRING "${word}" 1 -1 rest)
    string(TOUPPER "${first}" first)
    string(APPEND name "${first}${rest}")
  endforeach()
  set(${out} "${name}" PARENT_SCOPE)
endfunction()

# snell_add_shaders(<target> <files...>): an INTERFACE target whose include
# directory holds <stem>.spv.h for every shader given.
function(snell_add_shaders target)
  set(outdir "${CMAKE_CURRENT_BINARY_DIR}/spirv")
  set(headers "")
  foreach(source IN LISTS ARGN)
    get_filename_component(stem "${source}" NAME_WE)
    snell_shader_variable(variable "${source}")
    set(header "${outdir}/${stem}.spv.h")
    add_custom_command(
      OUTPUT "${header}"
      COMMAND "${CMAKE_COMMAND}" -E make_directory "${outdir}"
      COMMAND "${GLSLANG_VALIDATOR}" --quiet --target-env vulkan1.3 -g0 --vn "${variable}"
              --depfile "${header}.d" -o "${header}" "${CMAKE_CURRENT_SOURCE_DIR}/${source}"
      DEPENDS "${CMAKE_CURRENT_SOURCE_DIR}/${source}"
      DEPFILE "${header}.d"
      COMMENT "GLSL -> SPIR-V ${source}"
      VERBATIM)
    list(APPEND headers "${header}")
  endforeach()
  add_custom_target(${target}_compile DEPENDS ${headers})
  add_library(${target} INTERFACE)
  add_dependencies(${target} ${target}_compile)
  target_include_directories(${target} INTERFACE "${outdir}")
endfunction()
