# CPack: one Debian package, snell_VERSION_ARCH.deb, holding what
# `cmake --install` installs under /usr: the command, libsnell.so with its
# headers and CMake package, the Python module (with SNELL_BUILD_PYTHON) in
# /usr/lib/python3/dist-packages and the Blender add-on in Debian's Blender's
# add-on folder. `apt-get install ./snell_VERSION_ARCH.deb` on a Debian 12 node
# pulls in what it needs: the libraries found by dpkg-shlibdeps, plus what no
# binary links but snell needs at run time.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME snell)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_PACKAGE_CONTACT "The snell authors")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "refraction through deforming meshes, on Vulkan compute")
string(CONCAT CPACK_DEBIAN_PACKAGE_DESCRIPTION
       "snell ray traces glass and eye corneas through deforming meshes with plain\n"
       "Vulkan compute, on any GPU or on the CPU through Mesa's lavapipe. This\n"
       "package holds the snell command (render, bake, farm), the embedding library\n"
       "libsnell with its headers and CMake package, the Python module and the\n"
       "Blender add-on.")
set(CPACK_DEBIAN_PACKAGE_SECTION graphics)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# What no binary links: a Vulkan driver (lavapipe, for nodes without a GPU;
# a GPU's own driver comes from its vendor) and, for the module, Debian's
# CPython and numpy.
set(runtime_depends "mesa-vulkan-drivers")
if(SNELL_BUILD_PYTHON)
  string(APPEND runtime_depends ", python3 (>= 3.11), python3-numpy")
  set(CPACK_DEBIAN_PACKAGE_SUGGESTS "blender (>= 3.4)")
endif()
set(CPACK_DEBIAN_PACKAGE_DEPENDS "${runtime_depends}")
include(CPack)
