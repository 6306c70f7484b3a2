// Renders one viewport frame of a glTF file through the installed library
// and writes it as a binary PPM: consumer SCENE.glb OUT.ppm [WIDTH HEIGHT]
#include <snell/snell.h>

#include <cmath>
#include <cstdio>
#include <string>

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: consumer SCENE.glb OUT.ppm [WIDTH HEIGHT]\n");
    return 2;
  }
  try {
    snell::Device device = snell::Device::create();
    snell::Scene scene = snell::Scene::load(argv[1]);
    snell::Renderer renderer(device, scene);
    renderer.setTime(0.5);

    snell::View view;
    if (argc >= 5) view.width = uint32_t(std::stoul(argv[3])), view.height = uint32_t(std::stoul(argv[4]));
    view.sceneCamera = scene.cameraCount() > 0 ? 0 : -1;  // else View::camera's look-at
    std::vector<float> rgba = renderer.read(view);  // linear RGBA, row 0 at the top

    std::FILE* out = std::fopen(argv[2], "wb");
    if (!out) throw snell::Error(std::string("cannot write ") + argv[2]);
    std::fprintf(out, "P6\n%u %u\n255\n", view.width, view.height);
    for (size_t i = 0; i < rgba.size(); ++i) {
      if (i % 4 == 3) continue;  // PPM has no alpha
      float c = std::fmin(std::fmax(rgba[i], 0.0f), 1.0f);
      float srgb = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
      std::fputc(int(std::lround(srgb * 255.0f)), out);
    }
    std::fclose(out);
    std::printf("%s on %s: %ux%u, %llu pixels traced, to %s\n", scene.name().c_str(), device.name().c_str(), view.width,
                view.height, (unsigned long long)renderer.lastFrame().pixelsTraced, argv[2]);
  } catch (const snell::Error& e) {
    std::fprintf(stderr, "consumer: %s\n", e.what());
    return 1;
  }
}
