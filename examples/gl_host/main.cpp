// An OpenGL host, as a DCC viewport plug-in is: it draws its own scene (a
// gradient backdrop), and composites snell's viewport image over it each
// frame. snell renders into a Vulkan image whose memory OpenGL imports
// (GL_EXT_memory_object_fd); the two APIs hand the image over with shared
// semaphores (GL_EXT_semaphore_fd) where both drivers have them, else with a
// fence wait on snell's frame and glFinish on the host's.
//
//   gl_host SCENE.glb [--size WxH] [--time T] [--frames N] [--screenshot OUT.ppm]
//
// The frames animate from 0 to T seconds; the screenshot is of the last one.
#define GL_GLEXT_PROTOTYPES  // core 4.5 functions from libGL; the EXT ones are loaded below
#define GLFW_INCLUDE_GLCOREARB
#define GLFW_INCLUDE_GLEXT
#include <GLFW/glfw3.h>
#include <snell/snell.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace {

struct Options {
  std::string scene, screenshot;
  uint32_t width = 320, height = 240, frames = 60;
  double time = 1.0;
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw snell::Error(a + " needs a value");
      return argv[++i];
    };
    if (a == "--size") {
      if (std::sscanf(value().c_str(), "%ux%u", &o.width, &o.height) != 2 || !o.width || !o.height) {
        throw snell::Error("--size takes WIDTHxHEIGHT");
      }
    } else if (a == "--time") {
      o.time = std::stod(value());
    } else if (a == "--frames") {
      o.frames = uint32_t(std::stoul(value()));
      if (o.frames == 0) throw snell::Error("--frames must be at least 1");
    } else if (a == "--screenshot") {
      o.screenshot = value();
    } else if (a == "--help" || a == "-h") {
      std::printf("usage: gl_host SCENE.glb [--size WxH] [--time T] [--frames N] [--screenshot OUT.ppm]\n");
      std::exit(0);
    } else if (o.scene.empty() && a[0] != '-') {
      o.scene = a;
    } else {
      throw snell::Error("unknown argument " + a + " (gl_host --help)");
    }
  }
  if (o.scene.empty()) throw snell::Error("no scene given (gl_host --help)");
  return o;
}

// The extensions' entry points, which GL hands out at run time.
#define SNELL_GL_EXTENSION_FUNCTIONS(X)                                                                      \
  X(PFNGLCREATEMEMORYOBJECTSEXTPROC, glCreateMemoryObjectsEXT)                                                \
  X(PFNGLMEMORYOBJECTPARAMETERIVEXTPROC, glMemoryObjectParameterivEXT)                                        \
  X(PFNGLIMPORTMEMORYFDEXTPROC, glImportMemoryFdEXT)                                                          \
  X(PFNGLTEXTURESTORAGEMEM2DEXTPROC, glTextureStorageMem2DEXT)                                                \
  X(PFNGLDELETEMEMORYOBJECTSEXTPROC, glDeleteMemoryObjectsEXT)                                                \
  X(PFNGLGENSEMAPHORESEXTPROC, glGenSemaphoresEXT)                                                            \
  X(PFNGLIMPORTSEMAPHOREFDEXTPROC, glImportSemaphoreFdEXT)                                                    \
  X(PFNGLWAITSEMAPHOREEXTPROC, glWaitSemaphoreEXT)                                                            \
  X(PFNGLSIGNALSEMAPHOREEXTPROC, glSignalSemaphoreEXT)
namespace ext {
#define SNELL_DECLARE(type, name) type name = nullptr;
SNELL_GL_EXTENSION_FUNCTIONS(SNELL_DECLARE)
}  // namespace ext

void loadExtensionFunctions() {
#define SNELL_LOAD(type, name) ext::name = reinterpret_cast<type>(glfwGetProcAddress(#name));
  SNELL_GL_EXTENSION_FUNCTIONS(SNELL_LOAD)
  if (!ext::glImportMemoryFdEXT || !ext::glTextureStorageMem2DEXT) throw snell::Error("the GL driver lacks GL_EXT_memory_object_fd");
}

bool hasExtension(const char* name) {
  GLint count = 0;
  glGetIntegerv(GL_NUM_EXTENSIONS, &count);
  for (GLint i = 0; i < count; ++i) {
    if (std::strcmp(reinterpret_cast<const char*>(glGetStringi(GL_EXTENSIONS, GLuint(i))), name) == 0) return true;
  }
  return false;
}

GLuint program(const char* vertex, const char* fragment) {
  GLuint p = glCreateProgram();
  for (auto [type, source] : {std::pair{GL_VERTEX_SHADER, vertex}, std::pair{GL_FRAGMENT_SHADER, fragment}}) {
    GLuint s = glCreateShader(type);
    glShaderSource(s, 1, &source, nullptr);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
      char log[1024];
      glGetShaderInfoLog(s, sizeof log, nullptr, log);
      throw snell::Error(std::string("GL shader: ") + log);
    }
    glAttachShader(p, s);
    glDeleteShader(s);
  }
  glLinkProgram(p);
  return p;
}

// One triangle that covers the window.
const char* kFullScreen = R"(#version 450
void main() { gl_Position = vec4(vec2((gl_VertexID << 1) & 2, gl_VertexID & 2) * 2.0 - 1.0, 0.0, 1.0); })";

// The host's own scene: a backdrop from dark blue at the bottom to orange at the top.
const char* kBackdrop = R"(#version 450
layout(location = 0) uniform float height;
out vec4 colour;
void main() { colour = vec4(mix(vec3(0.1, 0.15, 0.45), vec3(0.95, 0.55, 0.1), gl_FragCoord.y / height), 1.0); })";

// snell's image, row 0 at the top, premultiplied alpha (blended ONE, ONE_MINUS_SRC_ALPHA).
const char* kComposite = R"(#version 450
layout(binding = 0) uniform sampler2D image;
out vec4 colour;
void main() {
  ivec2 size = textureSize(image, 0);
  colour = texelFetch(image, ivec2(gl_FragCoord.x, size.y - 1 - int(gl_FragCoord.y)), 0);
})";

void writePpm(const std::string& path, uint32_t width, uint32_t height) {
  std::vector<uint8_t> rgba(size_t(width) * height * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, GLsizei(width), GLsizei(height), GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
  std::string partial = path + ".partial";
  std::FILE* f = std::fopen(partial.c_str(), "wb");
  if (!f) throw snell::Error("cannot write " + path);
  std::fprintf(f, "P6\n%u %u\n255\n", width, height);
  for (uint32_t y = height; y-- > 0;) {  // GL's rows run bottom-up
    for (uint32_t x = 0; x < width; ++x) std::fwrite(&rgba[(size_t(y) * width + x) * 4], 1, 3, f);
  }
  bool ok = std::fclose(f) == 0;
  if (!ok || std::rename(partial.c_str(), path.c_str()) != 0) throw snell::Error("cannot write " + path);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    Options o = parse(argc, argv);
    if (!glfwInit()) throw snell::Error("GLFW cannot start (no display?)");
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);
    GLFWwindow* window = glfwCreateWindow(int(o.width), int(o.height), "snell in OpenGL", nullptr, nullptr);
    if (!window) throw snell::Error("no OpenGL 4.5 core context");
    glfwMakeContextCurrent(window);
    if (!hasExtension("GL_EXT_memory_object_fd")) throw snell::Error("the GL driver lacks GL_EXT_memory_object_fd");
    loadExtensionFunctions();

    // SNELL_VALIDATION=1 (as the tests run it): the Khronos layer checks every call.
    const char* validate = std::getenv("SNELL_VALIDATION");
    bool validation = validate && std::string(validate) == "1";
    snell::Device device = snell::Device::create({.validation = validation, .interop = true});
    snell::Scene scene = snell::Scene::load(o.scene);
    snell::Renderer renderer(device, scene);
    snell::View view;
    view.width = o.width, view.height = o.height;
    view.sceneCamera = scene.cameraCount() > 0 ? 0 : -1;
    view.transparentBackground = true;  // the host's backdrop shows where snell draws nothing

    // snell's image, imported by GL. The bytes are sRGB-encoded; GL reads
    // them as plain RGBA8 and they reach the window as they are.
    snell::SharedImage shared(device, o.width, o.height, VK_FORMAT_R8G8B8A8_SRGB);
    GLuint memory = 0, texture = 0;
    ext::glCreateMemoryObjectsEXT(1, &memory);
    GLint dedicated = shared.dedicated() ? GL_TRUE : GL_FALSE;
    ext::glMemoryObjectParameterivEXT(memory, GL_DEDICATED_MEMORY_OBJECT_EXT, &dedicated);
    ext::glImportMemoryFdEXT(memory, shared.memorySize(), GL_HANDLE_TYPE_OPAQUE_FD_EXT, shared.exportMemory());
    glCreateTextures(GL_TEXTURE_2D, 1, &texture);
    ext::glTextureStorageMem2DEXT(texture, 1, GL_RGBA8, GLsizei(o.width), GLsizei(o.height), memory, 0);
    if (glGetError() != GL_NO_ERROR) throw snell::Error("GL could not import snell's image");

    // Semaphores both ways where both sides have them: `rendered` (snell
    // wrote the image) and `released` (GL is done reading it).
    std::optional<snell::SharedSemaphore> rendered, released;
    GLuint renderedGl = 0, releasedGl = 0;
    bool semaphores = device.exportsSemaphores() && hasExtension("GL_EXT_semaphore_fd");
    if (semaphores) {
      rendered.emplace(device), released.emplace(device);
      ext::glGenSemaphoresEXT(1, &renderedGl);
      ext::glGenSemaphoresEXT(1, &releasedGl);
      ext::glImportSemaphoreFdEXT(renderedGl, GL_HANDLE_TYPE_OPAQUE_FD_EXT, rendered->exportFd());
      ext::glImportSemaphoreFdEXT(releasedGl, GL_HANDLE_TYPE_OPAQUE_FD_EXT, released->exportFd());
    }
    std::printf("gl_host: %s | snell on %s | hand-over: %s\n", glGetString(GL_RENDERER), device.name().c_str(),
                semaphores ? "shared semaphores" : "fence wait and glFinish");

    GLuint backdrop = program(kFullScreen, kBackdrop), composite = program(kFullScreen, kComposite);
    GLuint vertexArray = 0;
    glCreateVertexArrays(1, &vertexArray);
    glBindVertexArray(vertexArray);
    for (uint32_t frame = 0; frame < o.frames && !glfwWindowShouldClose(window); ++frame) {
      renderer.setTime(o.time * (frame + 1) / o.frames);
      VkImageLayout before = frame == 0 ? VK_IMAGE_LAYOUT_UNDEFINED : VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
      snell::Target target = shared.target(before, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
      if (semaphores) {
        snell::Sync sync{frame == 0 ? VK_NULL_HANDLE : released->handle(), VK_PIPELINE_STAGE_TRANSFER_BIT,
                         rendered->handle()};
        renderer.render(view, target, sync);
        GLenum layout = GL_LAYOUT_SHADER_READ_ONLY_EXT;
        ext::glWaitSemaphoreEXT(renderedGl, 0, nullptr, 1, &texture, &layout);
      } else {
        renderer.wait(renderer.render(view, target));
      }

      glDisable(GL_BLEND);
      glUseProgram(backdrop);
      glUniform1f(0, float(o.height));
      glDrawArrays(GL_TRIANGLES, 0, 3);
      glEnable(GL_BLEND);
      glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
      glUseProgram(composite);
      glBindTextureUnit(0, texture);
      glDrawArrays(GL_TRIANGLES, 0, 3);

      if (semaphores) {
        GLenum layout = GL_LAYOUT_SHADER_READ_ONLY_EXT;
        ext::glSignalSemaphoreEXT(releasedGl, 0, nullptr, 1, &texture, &layout);
      } else {
        glFinish();  // GL's reads of the image end before snell writes it again
      }
      if (frame + 1 == o.frames && !o.screenshot.empty()) writePpm(o.screenshot, o.width, o.height);
      glfwSwapBuffers(window);
      glfwPollEvents();
    }
    glFinish();
    device.waitIdle();
    if (device.validationMessages() > 0) {
      throw snell::Error(std::to_string(device.validationMessages()) + " validation messages (see above)");
    }
    if (!o.screenshot.empty()) std::printf("gl_host: wrote %s\n", o.screenshot.c_str());
    glDeleteTextures(1, &texture);
    ext::glDeleteMemoryObjectsEXT(1, &memory);
    glfwDestroyWindow(window);
    glfwTerminate();
    return 0;
  } catch (const snell::Error& e) {
    std::fprintf(stderr, "gl_host: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gl_host: %s\n", e.what());
    return 1;
  }
}
