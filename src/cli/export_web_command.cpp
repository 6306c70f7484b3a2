// `snell export-web SCENE -o DIR`: the Sky paper's web page, baked by the
// trace: a page that draws the glass from a sky8 refraction map with a few
// lines of WebGL, no 3D mesh and no framework.
#include "cli/commands.h"

#include "bake/refraction_bake.h"
#include "io/image_file.h"
#include "render/method.h"
#include "render/renderer.h"
#include "scene/evaluate.h"
#include "scene/png.h"
#include "scene/texture_mips.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>

#include <unistd.h>

namespace snell::cli {

namespace {

constexpr const char* kHtml = R"(<!doctype html>
<html>
<head>
<meta charset="utf-8">
<title>snell: %TITLE%</title>
<style>
html, body { margin: 0; background: #000; }
canvas { display: block; }
#status { position: absolute; left: 0; top: %HEIGHT%px; margin: 4px; color: #999; font: 12px sans-serif; }
</style>
</head>
<body>
<canvas id="snell" width="%WIDTH%" height="%HEIGHT%"></canvas>
<p id="status">loading</p>
<script src="images.js"></script>
<script src="snell-web.js"></script>
</body>
</html>
)";

// The script: four textures, one triangle over the canvas, one draw. The
// map's decode is the seed's GLSL line for line (docs/refraction-maps.md);
// the seed's mediump is highp here, as desktop GPUs run it either way.
constexpr const char* kScript = R"(// snell export-web: the glass of one view, drawn from a baked refraction map.
(function () {
  'use strict';
  var scriptMs = performance.now();
  var canvas = document.getElementById('snell');
  var status = document.getElementById('status');
  var gl = canvas.getContext('webgl2', { antialias: false, premultipliedAlpha: false, preserveDrawingBuffer: true });
  if (!gl) { status.textContent = 'this browser has no WebGL 2'; return; }

  var vertexSource =
    '#version 300 es\n' +
    'in vec2 position;\n' +
    'out vec2 v_texCoord;\n' +
    'void main() {\n' +
    '  v_texCoord = vec2(0.5 + 0.5 * position.x, 0.5 - 0.5 * position.y);\n' +
    '  gl_Position = vec4(position, 0.0, 1.0);\n' +
    '}\n';
  var fragmentSource =
    '#version 300 es\n' +
    'precision highp float;\n' +
    'uniform sampler2D u_normal;\n' +      // the refraction map, named as in the seed
    'uniform sampler2D u_diffuse;\n' +
    'uniform sampler2D u_weight;\n' +
    'uniform sampler2D u_reflection;\n' +  // the texture behind the glass: sRGB, its mips snell's
    'uniform float weightScale;\n' +
    'in vec2 v_texCoord;\n' +
    'out vec4 fragColor;\n' +
    'vec3 toLinear(vec3 c) { return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(0.04045, c)); }\n' +
    'vec3 toSrgb(vec3 c) {\n' +
    '  c = clamp(c, 0.0, 1.0);\n' +
    '  return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));\n' +
    '}\n' +
    'void main() {\n' +
    '  vec4 diffuse = texture(u_diffuse, v_texCoord);\n' +
    '  vec4 normal = texture(u_normal, v_texCoord);\n' +
    '  float u = normal.r * 16.0;\n' +
    '  float v = normal.g * 16.0;\n' +
    '  u += floor(normal.b * 16.0) * 16.0;\n' +
    '  v += mod(normal.b * 255.0, 16.0) * 16.0;\n' +
    '  u = u / 255.0;\n' +
    '  v = v / 255.0;\n' +
    '  vec3 colour = toLinear(diffuse.rgb);\n' +
    '  if (normal.a > 0.75) {\n' +
    '    vec4 weight = texture(u_weight, v_texCoord);\n' +  // alpha: the level of detail snell read at, x 16
    '    colour += weightScale * toLinear(weight.rgb) * textureLod(u_reflection, vec2(u, v), weight.a * 255.0 / 16.0).rgb;\n' +
    '  }\n' +
    '  fragColor = vec4(toSrgb(colour), 1.0);\n' +
    '}\n';

  function shader(type, source) {
    var s = gl.createShader(type);
    gl.shaderSource(s, source);
    gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
    return s;
  }
  var program = gl.createProgram();
  gl.attachShader(program, shader(gl.VERTEX_SHADER, vertexSource));
  gl.attachShader(program, shader(gl.FRAGMENT_SHADER, fragmentSource));
  gl.linkProgram(program);
  if (!gl.getProgramParameter(program, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(program));
  var compiledMs = performance.now();

  // The layers are reference data: never filtered (that cracks a map), bytes as they are.
  gl.pixelStorei(gl.UNPACK_COLORSPACE_CONVERSION_WEBGL, gl.NONE);
  gl.pixelStorei(gl.UNPACK_PREMULTIPLY_ALPHA_WEBGL, false);
  var layers = [
    { name: 'u_normal', images: [snellImages.map] },
    { name: 'u_diffuse', images: [snellImages.diffuse] },
    { name: 'u_weight', images: [snellImages.weight] },
    { name: 'u_reflection', images: snellImages.behind, srgb: true },
  ];
  var pending = 0;
  layers.forEach(function (layer) { pending += layer.images.length; });
  layers.forEach(function (layer, unit) {
    var texture = gl.createTexture();
    layer.images.forEach(function (source, level) {
      var image = new Image();
      image.onload = function () {
        gl.activeTexture(gl.TEXTURE0 + unit);
        gl.bindTexture(gl.TEXTURE_2D, texture);
        gl.texImage2D(gl.TEXTURE_2D, level, layer.srgb ? gl.SRGB8_ALPHA8 : gl.RGBA8, gl.RGBA, gl.UNSIGNED_BYTE, image);
        if (--pending === 0) draw();
      };
      image.onerror = function () { status.textContent = 'could not decode ' + layer.name; };
      image.src = source;
    });
  });

  function draw() {
    var decodedMs = performance.now();
    layers.forEach(function (layer, unit) {
      gl.activeTexture(gl.TEXTURE0 + unit);
      var last = layer.images.length - 1;
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAX_LEVEL, last);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, layer.srgb ? gl.LINEAR_MIPMAP_LINEAR : gl.NEAREST);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, layer.srgb ? gl.LINEAR : gl.NEAREST);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, layer.srgb ? gl[snellImages.wrapS] : gl.CLAMP_TO_EDGE);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, layer.srgb ? gl[snellImages.wrapT] : gl.CLAMP_TO_EDGE);
    });
    gl.useProgram(program);
    layers.forEach(function (layer, unit) { gl.uniform1i(gl.getUniformLocation(program, layer.name), unit); });
    gl.uniform1f(gl.getUniformLocation(program, 'weightScale'), snellImages.weightScale);
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer());
    gl.bufferData(gl.ARRAY_BUFFER, new Float32Array([-1, -1, 3, -1, -1, 3]), gl.STATIC_DRAW);
    var position = gl.getAttribLocation(program, 'position');
    gl.enableVertexAttribArray(position);
    gl.vertexAttribPointer(position, 2, gl.FLOAT, false, 0, 0);
    gl.viewport(0, 0, canvas.width, canvas.height);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    var pixel = new Uint8Array(4);
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);  // waits for the frame
    var ms = performance.now();
    status.textContent = 'first frame ' + ms.toFixed(1) + ' ms after navigation (script from ' + scriptMs.toFixed(1) +
      ' ms, shaders compiled by ' + compiledMs.toFixed(1) + ', images decoded by ' + decodedMs.toFixed(1) + ')';
    status.setAttribute('data-first-frame-ms', ms.toFixed(2));
    status.setAttribute('data-script-ms', scriptMs.toFixed(2));
    status.setAttribute('data-compiled-ms', compiledMs.toFixed(2));
    status.setAttribute('data-decoded-ms', decodedMs.toFixed(2));
  }
})();
)";

std::string base64(const std::vector<uint8_t>& bytes) {
  static const char* const kDigits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    uint32_t n = uint32_t(bytes[i]) << 16;
    if (i + 1 < bytes.size()) n |= uint32_t(bytes[i + 1]) << 8;
    if (i + 2 < bytes.size()) n |= bytes[i + 2];
    out += kDigits[(n >> 18) & 63];
    out += kDigits[(n >> 12) & 63];
    out += i + 1 < bytes.size() ? kDigits[(n >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kDigits[n & 63] : '=';
  }
  return out;
}

std::string replaced(std::string text, const std::string& key, const std::string& value) {
  for (size_t at = text.find(key); at != std::string::npos; at = text.find(key, at + value.size())) {
    text.replace(at, key.size(), value);
  }
  return text;
}

struct Options {
  ShotOptions shot;
  std::string output;
  std::string material;
};

int runExportWeb(const Options& o) {
  namespace fs = std::filesystem;
  // Nothing is made until the page is ready; a folder that cannot be made or written fails now.
  io::checkWritable(fs::is_directory(o.output) ? (fs::path(o.output) / "index.html").string() : o.output);
  BakeSetup setup = prepareBake("export-web", o.shot, o.material);
  const auto& [scene, material, start, pose, view, context, settings] = setup;
  render::Renderer renderer(*context, scene, pose);
  bake::RefractionBake baked = renderer.bakeRefractionMap(pose, settings);
  if (material) baked.behindMaterial = *material;
  if (baked.count(bake::Coverage::Lands) == 0) {
    throw std::runtime_error("export-web: " + view.description + ": " + bake::describe(baked, scene) +
                             "; the page would have no glass to draw");
  }

  // The viewport's picture at the baked pose, for everything but the glass that lands.
  render::ViewRequest request = render::methodView(render::Method::RefractionMap, settings, render::RasterOptions{});
  render::FrameRequest frame;
  frame.pose = &pose;
  frame.views.push_back(request);
  frame.readbacks.push_back({.view = 0});
  std::vector<glm::vec4> picture = renderer.wait(renderer.submit(frame)).views.at(0).composite;

  size_t pixels = baked.texels.size();
  float weightScale = 0.0f;
  for (size_t i = 0; i < pixels; ++i) {
    if (baked.coverage(i) != bake::Coverage::Lands) continue;
    const glm::vec4& w = baked.texels[i].weight;
    weightScale = std::max({weightScale, w.r, w.g, w.b});
  }
  weightScale = std::max(weightScale, 1e-6f);
  std::vector<uint8_t> diffuse(pixels * 4, 255), weight(pixels * 4, 255);
  for (size_t i = 0; i < pixels; ++i) {
    bool lands = baked.coverage(i) == bake::Coverage::Lands;
    glm::vec3 d = lands ? glm::vec3(baked.texels[i].shine) : glm::vec3(picture[i]);
    glm::vec3 w = lands ? glm::vec3(baked.texels[i].weight) / weightScale : glm::vec3(0.0f);
    for (int c = 0; c < 3; ++c) {
      diffuse[4 * i + size_t(c)] = io::linearToSrgb8(d[c]);
      weight[4 * i + size_t(c)] = io::linearToSrgb8(w[c]);
    }
    // The level of detail the trace read the texture at, in sixteenths (the page reads it there too).
    float lod = baked.texels[i].weight.w;
    if (lands) weight[4 * i + 3] = uint8_t(std::lround(std::clamp(std::isfinite(lod) ? lod : 0.0f, 0.0f, 15.9375f) * 16.0f));
  }
  const scene::Texture& behind =
      scene.textures.at(size_t(scene.materials.at(baked.behindMaterial).baseColorTexture.texture));
  bake::MapPixels sky8 = bake::encodeMap(bake::storedMap(baked, scene), bake::Encoding::Sky8);

  struct Layer {
    std::string key;
    std::string file;
    std::vector<uint8_t> png;
  };
  std::vector<Layer> layers = {
      {"map", "map.png", scene::encodePng(sky8.width, sky8.height, sky8.sky8)},
      {"diffuse", "diffuse.png", scene::encodePng(o.shot.width, o.shot.height, diffuse)},
      {"weight", "weight.png", scene::encodePng(o.shot.width, o.shot.height, weight)},
  };
  // The texture behind with snell's own mip chain (averaged in linear light), which the page reads as sRGB.
  std::vector<scene::MipLevel> chain = scene::mipChain(behind, true);
  for (size_t level = 0; level < chain.size(); ++level) {
    layers.push_back({"behind", "behind-" + std::to_string(level) + ".png",
                      scene::encodePng(chain[level].width, chain[level].height, chain[level].rgba)});
  }
  auto wrap = [](bool repeat, bool mirror) { return mirror ? "MIRRORED_REPEAT" : repeat ? "REPEAT" : "CLAMP_TO_EDGE"; };
  std::string images = "// snell export-web: the page's images as data: URIs.\nvar snellImages = {\n";
  char scale[64];
  std::snprintf(scale, sizeof scale, "%.9g", double(weightScale));
  images += "  weightScale: " + std::string(scale) + ",\n  wrapS: '" + wrap(behind.repeatS, behind.mirrorS) +
            "',\n  wrapT: '" + wrap(behind.repeatT, behind.mirrorT) + "',\n  behind: [\n";
  for (const Layer& l : layers) {
    if (l.key == "behind") images += "    'data:image/png;base64," + base64(l.png) + "',\n";
  }
  images += "  ],\n";
  for (const Layer& l : layers) {
    if (l.key != "behind") images += "  " + l.key + ": 'data:image/png;base64," + base64(l.png) + "',\n";
  }
  images += "};\n";
  std::string title = xmlEscape((o.shot.eye ? std::string("the procedural eye") : fs::path(o.shot.input).filename().string()) +
                                  ", " + view.description);
  std::string html = replaced(replaced(replaced(kHtml, "%TITLE%", title), "%WIDTH%", std::to_string(o.shot.width)),
                              "%HEIGHT%", std::to_string(o.shot.height));
  // A new folder appears whole (written beside it, then renamed); into an
  // existing one each file is replaced whole, the page last, so it exists
  // only once all it loads does.
  fs::path dir(o.output);
  bool fresh = !fs::exists(dir);
  fs::path writing = fresh ? fs::path(dir.string() + ".partial-" + std::to_string(::getpid())) : dir;
  try {
    if (fresh) fs::create_directory(writing);
    for (const Layer& l : layers) io::writeTextFile((writing / l.file).string(), std::string(l.png.begin(), l.png.end()));
    io::writeTextFile((writing / "images.js").string(), images);
    io::writeTextFile((writing / "snell-web.js").string(), kScript);
    io::writeTextFile((writing / "index.html").string(), html);
    if (fresh) fs::rename(writing, dir);
  } catch (...) {
    std::error_code ignored;
    if (fresh) fs::remove_all(writing, ignored);
    throw;
  }

  uintmax_t pageBytes = fs::file_size(dir / "index.html") + fs::file_size(dir / "snell-web.js") + fs::file_size(dir / "images.js");
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("wrote %s: %ux%u, %s, %s, %.2f s\n  %s\n  the page loads %ju bytes: index.html %ju, snell-web.js %ju, "
              "images.js %ju\n",
              (dir / "index.html").string().c_str(), o.shot.width, o.shot.height, view.description.c_str(),
              context->facts().name.c_str(), seconds, bake::describe(baked, scene).c_str(), pageBytes,
              fs::file_size(dir / "index.html"), fs::file_size(dir / "snell-web.js"), fs::file_size(dir / "images.js"));
  return validationExitCode(*context);
}

}  // namespace

void addExportWeb(CLI::App& parent, Runner& run) {
  auto o = std::make_shared<Options>();
  CLI::App* sub = parent.add_subcommand("export-web", "a self-contained WebGL page drawing the glass from a sky8 map");
  describe(*sub,
      "Writes a self-contained web page that draws one view of the scene the way the\n"
      "Sky paper's page draws its glass: no mesh and no ray tracing in the browser,\n"
      "only a refraction map baked by the GPU trace (sky8, decoded in the fragment\n"
      "shader exactly as the seed's GLSL decodes it), the texture behind the glass,\n"
      "and the diffuse layer. It opens from the file system in any WebGL 2 browser.\n"
      "\n"
      "DIR gets:\n"
      "  index.html     the page: a canvas the size of the view\n"
      "  snell-web.js   the WebGL script (no framework)\n"
      "  images.js      the four images as data: URIs (a page opened from the file\n"
      "                 system may not read image files into WebGL)\n"
      "  map.png        the refraction map (sky8; A: 1 lands, 1/2 marked, 0 not glass)\n"
      "  behind-N.png   the texture behind the glass, level N of snell's mip chain\n"
      "  diffuse.png    what the glass adds (reflections, highlights), and the rest of\n"
      "                 the picture drawn by the viewport (sRGB)\n"
      "  weight.png     what the texture behind is multiplied by, over weightScale\n"
      "                 (sRGB), and in alpha the level of detail it is read at x 16\n"
      "The PNGs are the same images as images.js holds, for inspection; the page\n"
      "loads only index.html and the two scripts. It shows, on the page, the time\n"
      "from navigation to its first frame.\n"
      "\n"
      "A pixel of the page is diffuse + weightScale x weight x behind(map's UV) in\n"
      "linear light: what 'snell render --method refraction-map' draws at the baked\n"
      "pose, the texture read trilinearly at the level of detail the trace read it\n"
      "at, from the same mip chain, but by the browser's sampler in 8-bit sRGB.");
  sub->footer(kHelpFooter);
  o->shot.addTo(*sub);
  sub->add_option("-o,--output", o->output, "the folder to write (made if missing; files in it are replaced)")
      ->required()
      ->type_name("DIR");
  sub->add_option("--material", o->material, "the surface behind (default: the one most glass pixels land on)")
      ->type_name("NAME|INDEX");
  sub->callback([o, &run] {
    o->shot.require("export-web");
    run = [o] { return runExportWeb(*o); };
  });
}

}  // namespace snell::cli
