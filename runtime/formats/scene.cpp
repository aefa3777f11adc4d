// Scene files (thesis C.3): read, applied to the Show, and written. Terrain grids from height
// maps (§4.6).

#include "runtime/formats/scene.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <fmt/format.h>

namespace basalt::formats {

runtime::Material SceneMaterial::toMaterial() const {
  runtime::Material m;
  m.name = "scene material";
  m.ambient = ambient;
  m.diffuse = diffuse;
  m.specular = specular;
  m.emissive = emission;
  m.shininess = shininess;
  return m;
}

namespace {

std::uint32_t col(std::size_t offset) { return static_cast<std::uint32_t>(offset) + 1; }

class SceneParser {
 public:
  SceneParser(const std::string& name, const LoadOptions& options)
      : d_(name, options.limits.maxWarnings, options.logWarnings), limits_(options.limits) {}

  Result<SceneDescription> parse(std::string_view bytes, std::vector<Diagnostic>& warnings) {
    auto text = decodeText(std::string(bytes), d_);
    if (!text) return std::unexpected(text.error());
    LineReader lines(*text);
    while (auto raw = lines.next()) {
      line_ = *raw;
      if (const auto hash = line_.find('#'); hash != std::string_view::npos) line_ = line_.substr(0, hash);
      lineNumber_ = lines.number();
      std::size_t errorAt = 0;
      if (!splitStatementItems(line_, items_, errorAt)) {
        d_.warn(lineNumber_, col(errorAt), "'[' is not closed by ']'; the line is skipped");
        continue;
      }
      if (items_.empty()) continue;
      statement();
    }
    wholeFileChecks();
    scene_.finalMaterial = material_;
    for (Diagnostic& w : d_.finish()) warnings.push_back(std::move(w));
    return std::move(scene_);
  }

 private:
  void warnAt(std::size_t offset, std::string message) { d_.warn(lineNumber_, col(offset), std::move(message)); }

  /// The values of item `i`: its bracket contents, or (for a bare keyword) the words after it.
  std::vector<std::string_view> values(std::size_t i) const {
    if (items_[i].bracketed) return items_[i].args;
    std::vector<std::string_view> out;
    for (std::size_t k = i + 1; k < items_.size(); ++k) {
      std::string_view word = items_[k].name;
      while (!word.empty()) {
        const std::size_t comma = word.find(',');
        if (comma != 0) out.push_back(word.substr(0, comma));
        if (comma == std::string_view::npos) break;
        word.remove_prefix(comma + 1);
      }
      for (std::string_view a : items_[k].args) out.push_back(a);
    }
    return out;
  }

  bool numbers(const StatementItem& item, const std::vector<std::string_view>& v, float* out, std::size_t n) {
    if (v.size() != n) {
      warnAt(item.offset,
             fmt::format("'{}' needs {} value{}, not {}; skipped", item.name, n, n == 1 ? "" : "s", v.size()));
      return false;
    }
    for (std::size_t k = 0; k < n; ++k) {
      if (!parseFloat(v[k], out[k]) || !std::isfinite(out[k])) {
        warnAt(static_cast<std::size_t>(v[k].data() - line_.data()),
               fmt::format("'{}' is not a finite number; '{}' skipped", v[k], item.name));
        return false;
      }
    }
    return true;
  }

  bool vec3(const StatementItem& item, const std::vector<std::string_view>& v, Vec3& out) {
    float f[3];
    if (!numbers(item, v, f, 3)) return false;
    out = {f[0], f[1], f[2]};
    return true;
  }

  /// A skipped statement leaves `out` as it was (parseFloat may have written a prefix's value).
  bool scalar(const StatementItem& item, const std::vector<std::string_view>& v, float& out) {
    float value = 0;
    if (!numbers(item, v, &value, 1)) return false;
    out = value;
    return true;
  }

  /// A colour of 0..255 integers (a value with a fraction means 0..1), clamped with a warning.
  bool colour(const StatementItem& item, const std::vector<std::string_view>& v, runtime::Color3& out) {
    float f[3];
    if (!numbers(item, v, f, 3)) return false;
    bool fractional = false;
    for (std::string_view t : v) fractional = fractional || t.find_first_of(".eE") != std::string_view::npos;
    const float top = fractional ? 1.0f : 255.0f;
    bool clamped = false;
    for (float& c : f) {
      if (c < 0 || c > top) {
        clamped = true;
        c = std::clamp(c, 0.0f, top);
      }
      c /= top;
    }
    if (clamped) {
      warnAt(item.offset,
             fmt::format("'{}' has values outside 0..{}; they were clamped", item.name, fractional ? "1" : "255"));
    }
    out = {f[0], f[1], f[2]};
    return true;
  }

  /// The path after the keyword, up to the first bracketed item.
  std::string_view pathArgument(std::size_t& at) const {
    const StatementItem& key = items_[0];
    std::size_t start = key.offset + key.name.size();
    std::size_t end = line_.size();
    for (std::size_t k = 1; k < items_.size(); ++k) {
      if (items_[k].bracketed) {
        end = items_[k].offset;
        break;
      }
    }
    std::string_view p = trim(line_.substr(start, end - start));
    at = p.empty() ? start : static_cast<std::size_t>(p.data() - line_.data());
    return p;
  }

  void statement() {
    const StatementItem& key = items_[0];
    const std::string k = lowerAscii(key.name);
    const auto v = values(0);
    if (k == "viewport") {
      viewportLine_ = lineNumber_;
      return viewport();
    }
    if (k == "projection") {
      projectionLine_ = lineNumber_;
      return projection();
    }
    if (k == "fog") return fog();
    if (k == "light") return light();
    if (k == "import" || k == "importdir" || k == "terrain") return source(k);
    if (k == "eyespacing") {
      if (scalar(key, v, scene_.eyeSpacing) && !(scene_.eyeSpacing >= 0)) scene_.eyeSpacing = 0.04f;
    } else if (k == "bgcolor") {
      colour(key, v, scene_.background);
    } else if (k == "background" || k == "skybox") {
      std::size_t at = 0;
      const std::string_view p = pathArgument(at);
      if (p.empty()) {
        warnAt(key.offset, fmt::format("'{}' needs an image file; skipped", key.name));
        return;
      }
      (k == "background" ? scene_.backgroundImage : scene_.skybox) = std::string(p);
    } else if (k == "mapmin") {
      if (vec3(key, v, scene_.mapMin)) mapMinLine_ = lineNumber_;
    } else if (k == "mapmax") {
      if (vec3(key, v, scene_.mapMax)) mapMaxLine_ = lineNumber_;
    } else if (k == "position") {
      if (vec3(key, v, scene_.position)) positionLine_ = lineNumber_;
    } else if (k == "rotation") {
      vec3(key, v, scene_.rotation);
    } else if (k == "positionchange") {
      scalar(key, v, scene_.positionChange);
    } else if (k == "rotationchange") {
      scalar(key, v, scene_.rotationChange);
    } else if (k == "emission") {
      colour(key, v, material_.emission);
    } else if (k == "ambient") {
      colour(key, v, material_.ambient);
    } else if (k == "diffuse") {
      colour(key, v, material_.diffuse);
    } else if (k == "specular") {
      colour(key, v, material_.specular);
    } else if (k == "shininess") {
      float s = 0;
      if (scalar(key, v, s)) {
        if (s < 0 || s > 128) warnAt(key.offset, "shininess is 0..128 (OpenGL's range); clamped");
        material_.shininess = std::clamp(s, 0.0f, 128.0f);
      }
    } else {
      warnAt(key.offset, fmt::format("'{}' is not a scene statement; the line is skipped", key.name));
    }
  }

  /// Calls `handle(item, values)` for each `name[...]` after the keyword; warns about the rest.
  template <typename Handle>
  void subItems(std::string_view statementName, Handle&& handle) {
    for (std::size_t i = 1; i < items_.size(); ++i) {
      const StatementItem& item = items_[i];
      if (!item.bracketed) {
        warnAt(item.offset, fmt::format("'{}' in '{}' needs its value in brackets, as in name[1]; skipped", item.name,
                                        statementName));
        continue;
      }
      if (!handle(lowerAscii(item.name), item)) {
        warnAt(item.offset, fmt::format("'{}' is not part of '{}'; skipped", item.name, statementName));
      }
    }
  }

  void viewport() {
    std::array<std::int32_t, 4> vp = scene_.viewport.value_or(std::array<std::int32_t, 4>{0, 0, 0, 0});
    bool any = false;
    subItems("viewport", [&](const std::string& name, const StatementItem& item) {
      if (name != "position" && name != "resolution") return false;
      const std::size_t first = name == "position" ? 0 : 2;
      if (item.args.size() != 2) {
        warnAt(item.offset, fmt::format("'{}' needs 2 whole numbers; skipped", item.name));
        return true;
      }
      std::int64_t a = 0, b = 0;
      if (!parseInt(item.args[0], a) || !parseInt(item.args[1], b) || std::llabs(a) > 100000 ||
          std::llabs(b) > 100000 || (first == 2 && (a < 0 || b < 0))) {
        warnAt(item.argsOffset, fmt::format("'{}' needs 2 whole numbers in pixels; skipped", item.name));
        return true;
      }
      vp[first] = static_cast<std::int32_t>(a);
      vp[first + 1] = static_cast<std::int32_t>(b);
      any = true;
      return true;
    });
    if (any) scene_.viewport = vp;
  }

  void projection() {
    subItems("projection", [&](const std::string& name, const StatementItem& item) {
      float v = 0;
      if (name == "fov") {
        if (scalar(item, item.args, v)) {
          if (v > 0 && v < 180) {
            scene_.fieldOfView = v;
          } else {
            warnAt(item.offset, "fov is an angle between 0 and 180 degrees; skipped");
          }
        }
      } else if (name == "nearclip" || name == "farclip") {
        if (scalar(item, item.args, v)) {
          if (v > 0) {
            (name == "nearclip" ? scene_.nearClip : scene_.farClip) = v;
          } else {
            warnAt(item.offset, fmt::format("{} must be more than 0; skipped", item.name));
          }
        }
      } else {
        return false;
      }
      return true;
    });
    if (scene_.farClip <= scene_.nearClip) {
      warnAt(items_[0].offset, "farclip is not beyond nearclip; farclip is set to 10000 times nearclip");
      scene_.farClip = scene_.nearClip * 10000.0f;
    }
  }

  void fog() {
    SceneFog f = scene_.fog.value_or(SceneFog{});
    subItems("fog", [&](const std::string& name, const StatementItem& item) {
      if (name == "start") {
        scalar(item, item.args, f.start);
      } else if (name == "end") {
        scalar(item, item.args, f.end);
      } else if (name == "density") {
        scalar(item, item.args, f.density);
      } else if (name == "color" || name == "colour") {
        colour(item, item.args, f.color);
      } else if (name == "function") {
        const std::string fn = item.args.size() == 1 ? lowerAscii(item.args[0]) : std::string();
        if (fn == "linear") {
          f.function = SceneFogFunction::kLinear;
        } else if (fn == "exp") {
          f.function = SceneFogFunction::kExp;
        } else if (fn == "exp2") {
          f.function = SceneFogFunction::kExp2;
        } else {
          warnAt(item.offset, "the fog function is exp, exp2 or linear; skipped");
        }
      } else {
        return false;
      }
      return true;
    });
    scene_.fog = f;
  }

  void light() {
    if (scene_.lights.size() + 1 >= runtime::kMaxLights) {
      warnAt(items_[0].offset, fmt::format("more than {} lights; this one is skipped", runtime::kMaxLights - 1));
      return;
    }
    SceneLight l;
    subItems("light", [&](const std::string& name, const StatementItem& item) {
      if (name == "position") {
        float p[4];
        if (numbers(item, item.args, p, 4)) l.position = {p[0], p[1], p[2], p[3]};
      } else if (name == "ambient") {
        colour(item, item.args, l.ambient);
      } else if (name == "diffuse") {
        colour(item, item.args, l.diffuse);
      } else if (name == "specular") {
        colour(item, item.args, l.specular);
      } else {
        return false;
      }
      return true;
    });
    scene_.lights.push_back(l);
  }

  void source(const std::string& keyword) {
    if (scene_.sources.size() >= limits_.maxImports) {
      warnAt(items_[0].offset, fmt::format("more than {} imports; this one is skipped", limits_.maxImports));
      return;
    }
    SceneSource s;
    s.kind = keyword == "import"      ? SceneSource::Kind::kModel
             : keyword == "importdir" ? SceneSource::Kind::kDirectory
                                      : SceneSource::Kind::kTerrain;
    s.material = material_;
    s.line = lineNumber_;
    std::size_t at = 0;
    s.path = std::string(pathArgument(at));
    if (s.path.empty()) {
      warnAt(items_[0].offset, fmt::format("'{}' needs a file name; skipped", items_[0].name));
      return;
    }
    if (s.kind == SceneSource::Kind::kTerrain) {
      for (std::size_t i = 1; i < items_.size(); ++i) {
        const StatementItem& item = items_[i];
        if (!item.bracketed) continue;  // part of the path
        const std::string name = lowerAscii(item.name);
        if (name == "amplitude") {
          scalar(item, item.args, s.amplitude);
        } else if (name == "position") {
          vec3(item, item.args, s.position);
        } else {
          warnAt(item.offset, fmt::format("'{}' is not part of 'terrain'; skipped", item.name));
        }
      }
    }
    scene_.sources.push_back(std::move(s));
  }

  /// What only the whole file shows: values that parse but that the camera cannot honour as
  /// written (thesis §4.3.1 and §4.3.4), each named at its line.
  void wholeFileChecks() {
    if (scene_.viewport && ((*scene_.viewport)[2] == 0 || (*scene_.viewport)[3] == 0)) {
      d_.warn(viewportLine_, 1,
              "the viewport has no area (give resolution[width,height] in pixels); the scene fills its view instead");
    }
    const Vec3 &lo = scene_.mapMin, &hi = scene_.mapMax;
    if (lo.x > hi.x || lo.y > hi.y || lo.z > hi.z) {
      d_.warn(std::max(mapMinLine_, mapMaxLine_), 1,
              "mapmin is beyond mapmax on some axis; the viewer is held at mapmax there when it moves");
    } else {
      const Vec3& p = scene_.position;
      if (p.x < lo.x || p.y < lo.y || p.z < lo.z || p.x > hi.x || p.y > hi.y || p.z > hi.z) {
        d_.warn(positionLine_ ? positionLine_ : std::max(mapMinLine_, mapMaxLine_), 1,
                "the viewer's start position is outside mapmin..mapmax; its first move puts it back inside");
      }
    }
    // A 24-bit depth buffer resolves about one part in 2^24 of 1/near - 1/far.
    if (scene_.farClip / scene_.nearClip > 1e6f) {
      d_.warn(projectionLine_, 1,
              fmt::format("farclip is {:g} times nearclip: the depth buffer cannot keep surfaces apart at that "
                          "range (they flicker through each other); raise nearclip",
                          scene_.farClip / scene_.nearClip));
    }
  }

  Diagnostics d_;
  const Limits& limits_;
  std::uint32_t viewportLine_ = 0, projectionLine_ = 0, positionLine_ = 0, mapMinLine_ = 0, mapMaxLine_ = 0;
  SceneDescription scene_;
  SceneMaterial material_;
  std::string_view line_;
  std::uint32_t lineNumber_ = 0;
  std::vector<StatementItem> items_;
};

}  // namespace

Result<SceneDescription> parseSceneText(std::string_view text, const std::string& name, const LoadOptions& options,
                                        std::vector<Diagnostic>& warnings) {
  SceneParser parser(name, options);
  return parser.parse(text, warnings);
}

// ---- Terrain ------------------------------------------------------------------------------------

namespace {

float sampleHeight(const Image& image, std::uint32_t x, std::uint32_t y) {
  const std::size_t index = (std::size_t{y} * image.width + x) * image.channels;
  const auto value = [&](std::size_t c) -> float {
    switch (image.type) {
      case ChannelType::kU8: return static_cast<float>(image.pixels[index + c]) / 255.0f;
      case ChannelType::kU16: {
        std::uint16_t v = 0;
        std::memcpy(&v, image.pixels.data() + (index + c) * 2, 2);
        return static_cast<float>(v) / 65535.0f;
      }
      case ChannelType::kF32: {
        float v = 0;
        std::memcpy(&v, image.pixels.data() + (index + c) * 4, 4);
        return std::isfinite(v) ? v : 0.0f;
      }
    }
    return 0.0f;
  };
  if (image.channels >= 3) return 0.2126f * value(0) + 0.7152f * value(1) + 0.0722f * value(2);
  return value(0);
}

}  // namespace

Result<Terrain> makeTerrain(const Image& heightMap, float amplitude, const Vec3& position, const std::string& name,
                            const Limits& limits) {
  const std::uint32_t w = heightMap.width, h = heightMap.height;
  if (w < 2 || h < 2) {
    return fail(Errc::kInvalidArgument,
                fmt::format("a height map needs at least 2 x 2 pixels, this one has {} x {}", w, h));
  }
  if (w > limits.maxTerrainSide || h > limits.maxTerrainSide) {
    return fail(Errc::kResourceExhausted,
                fmt::format("the height map is {} x {} pixels, more than the limit of {} a side; scale it down", w, h,
                            limits.maxTerrainSide));
  }
  if (heightMap.channels < 1 || heightMap.channels > 4 ||
      heightMap.pixels.size() < std::size_t{w} * h * heightMap.channels * channelBytes(heightMap.type)) {
    return fail(Errc::kInvalidArgument, "the height map's pixels do not match its size");
  }
  if (!std::isfinite(amplitude) || !std::isfinite(position.x) || !std::isfinite(position.y) ||
      !std::isfinite(position.z)) {
    return fail(Errc::kInvalidArgument, "the terrain's amplitude and position must be finite numbers");
  }
  auto heights = std::make_shared<runtime::HeightField>();
  heights->columns = w;
  heights->rows = h;
  heights->spacing = 1.0f;
  heights->origin = position;
  heights->heights.resize(std::size_t{w} * h);
  for (std::uint32_t y = 0; y < h; ++y) {
    for (std::uint32_t x = 0; x < w; ++x)
      heights->heights[std::size_t{y} * w + x] = sampleHeight(heightMap, x, y) * amplitude;
  }
  auto mesh = std::make_shared<runtime::Mesh>();
  runtime::Mesh& m = *mesh;
  const std::size_t count = std::size_t{w} * h;
  m.positions.resize(count);
  m.normals.resize(count);
  m.texcoords.resize(count);
  const auto at = [&](std::uint32_t x, std::uint32_t y) { return heights->heights[std::size_t{y} * w + x]; };
  for (std::uint32_t y = 0; y < h; ++y) {
    for (std::uint32_t x = 0; x < w; ++x) {
      const std::size_t i = std::size_t{y} * w + x;
      m.positions[i] = {static_cast<float>(x), at(x, y), static_cast<float>(y)};
      const float dx = at(std::min(x + 1, w - 1), y) - at(x > 0 ? x - 1 : 0, y);
      const float dz = at(x, std::min(y + 1, h - 1)) - at(x, y > 0 ? y - 1 : 0);
      m.normals[i] = normalize(Vec3{-dx, 2.0f, -dz});
      m.texcoords[i] = {static_cast<float>(x) / static_cast<float>(w - 1),
                        static_cast<float>(y) / static_cast<float>(h - 1)};
    }
  }
  const std::size_t cells = std::size_t{w - 1} * (h - 1);
  m.triangles.reserve(cells * 6);
  m.edges.reserve(cells * 8);
  m.facetSizes.assign(cells, 4);
  for (std::uint32_t y = 0; y + 1 < h; ++y) {
    for (std::uint32_t x = 0; x + 1 < w; ++x) {
      // Counter-clockwise seen from above (+Y).
      const auto a = static_cast<std::uint32_t>(y * w + x);
      const std::uint32_t b = a + w, c = a + w + 1, d = a + 1;
      m.triangles.insert(m.triangles.end(), {a, b, c, a, c, d});
      m.edges.insert(m.edges.end(), {a, b, b, c, c, d, d, a});
    }
  }
  runtime::MeshPart part;
  part.name = name;
  part.triangleIndexCount = static_cast<std::uint32_t>(m.triangles.size());
  part.edgeIndexCount = static_cast<std::uint32_t>(m.edges.size());
  part.facetCount = static_cast<std::uint32_t>(cells);
  m.parts.push_back(std::move(part));
  Terrain terrain;
  terrain.mesh = std::move(mesh);
  terrain.heights = std::move(heights);
  terrain.name = name;
  return terrain;
}

// ---- Loading and applying ----------------------------------------------------------------------

Result<LoadedScene> loadScene(const std::filesystem::path& path, const LoadOptions& options) {
  auto bytes = readFileBytes(path, options.limits.maxFileBytes);
  if (!bytes) return std::unexpected(bytes.error());
  LoadedScene scene;
  scene.path = path;
  if (lowerAscii(path.extension().string()) != ".sce") {
    scene.warnings.push_back({path.string(), "scene files should end in .sce (thesis C.3); read anyway"});
  }
  auto description = parseSceneText(*bytes, path.string(), options, scene.warnings);
  if (!description) return std::unexpected(description.error());
  scene.description = std::move(*description);
  const std::filesystem::path folder = path.parent_path();
  const auto where = [&](const SceneSource& s) { return fmt::format("{}:{}", path.string(), s.line); };
  std::size_t imported = 0;
  const auto importModel = [&](const std::filesystem::path& file, const SceneSource& s) {
    if (++imported > options.limits.maxImports) {
      scene.warnings.push_back(
          {where(s), fmt::format("more than {} models; {} is skipped", options.limits.maxImports, file.string())});
      return;
    }
    auto model = loadModel(file, options);
    if (!model) {
      scene.warnings.push_back({where(s), fmt::format("the model could not be imported, the scene goes on without "
                                                      "it: {}",
                                                      model.error().describe())});
      return;
    }
    for (Diagnostic& w : model->warnings) scene.warnings.push_back(w);
    // The thesis applies the scene's material state to every model it imports (§4.3.5); a
    // part with a material of its own (an MTL file's) keeps that one instead, and says so.
    bool ownMaterials = false;
    for (const ModelObject& o : model->objects) {
      if (!o.mesh) continue;
      for (const runtime::MeshPart& part : o.mesh->parts) ownMaterials = ownMaterials || part.material >= 0;
    }
    if (ownMaterials) {
      scene.warnings.push_back(
          {where(s), fmt::format("{} has materials of its own (MTL); its parts that use one keep it instead of the "
                                 "scene's material state",
                                 file.filename().string())});
    }
    scene.models.push_back({std::move(*model), s.material});
  };
  for (const SceneSource& s : scene.description.sources) {
    switch (s.kind) {
      case SceneSource::Kind::kModel: {
        const ResolvedPath file = resolveReferencedFile(s.path, folder, options.searchPaths);
        importModel(file.path, s);
        break;
      }
      case SceneSource::Kind::kDirectory: {
        std::filesystem::path dir = std::filesystem::path(s.path);
        if (dir.is_relative()) dir = folder / dir;
        std::error_code ec;
        std::vector<std::filesystem::path> files;
        std::filesystem::directory_iterator it(dir, ec);
        if (ec) {
          scene.warnings.push_back(
              {where(s), fmt::format("cannot list the folder {}: {}", dir.string(), ec.message())});
          break;
        }
        for (const auto& entry : it) {
          const std::string ext = lowerAscii(entry.path().extension().string());
          if ((ext == ".obj" || ext == ".off") && entry.is_regular_file(ec)) files.push_back(entry.path());
          if (files.size() > options.limits.maxImports) break;
        }
        std::sort(files.begin(), files.end());
        if (files.empty())
          scene.warnings.push_back({where(s), fmt::format("{} has no .obj or .off files", dir.string())});
        for (const auto& f : files) importModel(f, s);
        break;
      }
      case SceneSource::Kind::kTerrain: {
        const ResolvedPath file = resolveReferencedFile(s.path, folder, options.searchPaths);
        if (!options.decodeImage) {
          scene.warnings.push_back({where(s), "no image decoder was given, so the terrain is skipped"});
          break;
        }
        auto image = options.decodeImage(file.path);
        if (!image) {
          scene.warnings.push_back({where(s), fmt::format("the terrain's height map could not be read, the scene goes "
                                                          "on without it: {}",
                                                          image.error().describe())});
          break;
        }
        auto terrain = makeTerrain(*image, s.amplitude, s.position, file.path.stem().string(), options.limits);
        if (!terrain) {
          scene.warnings.push_back({where(s), fmt::format("the terrain is skipped: {}", terrain.error().message())});
          break;
        }
        scene.terrains.push_back({std::move(*terrain), s.material});
        break;
      }
    }
  }
  for (const std::string* image : {&scene.description.backgroundImage, &scene.description.skybox}) {
    if (image->empty()) continue;
    if (!resolveReferencedFile(*image, folder, options.searchPaths).found) {
      scene.warnings.push_back(
          {path.string(), fmt::format("the image '{}' was not found; the background stays a colour "
                                      "until it appears",
                                      *image)});
    }
  }
  return scene;
}

void applyScene(runtime::Show& show, const LoadedScene& scene, std::vector<Diagnostic>* warnings) {
  std::vector<Diagnostic> local;
  std::vector<Diagnostic>& out = warnings ? *warnings : local;
  const SceneDescription& d = scene.description;
  show.clear();
  std::vector<runtime::Material> materials;
  materials.reserve(scene.models.size() + scene.terrains.size());
  std::vector<ModelImport> imports;
  for (const LoadedScene::Import& i : scene.models) {
    materials.push_back(i.material.toMaterial());
    imports.push_back({&i.model, &materials.back(), true});
  }
  addModels(show, imports, out);
  for (const LoadedScene::PlacedTerrain& t : scene.terrains) {
    runtime::SceneNode node;
    node.name = t.terrain.name;
    node.mesh = t.terrain.mesh;
    node.local = Mat4::translation(t.terrain.heights->origin);
    node.source = scene.path.string();
    const runtime::NodeId id = show.addTerrain(std::move(node), t.terrain.heights);
    materials.push_back(t.material.toMaterial());
    for (runtime::PartId part : show.nodes()[id].partIds) applySceneMaterial(show, part, materials.back());
  }
  if (!d.lights.empty()) {
    // Thesis §4.2.4 (OpenGL): the global ambient colour (OpenGL's default 0.2, which a scene
    // file cannot change) scaled by the material's ambient colour, then each light with its
    // own ambient, diffuse and specular colours, in the scene's units.
    auto& lights = show.lights();
    for (runtime::Light& l : lights) l.on = false;
    lights[0] = runtime::Light{};
    lights[0].on = true;
    lights[0].type = runtime::LightType::kAmbient;
    lights[0].color = kSceneGlobalAmbient;
    for (std::size_t i = 0; i < d.lights.size() && i + 1 < lights.size(); ++i) {
      const SceneLight& s = d.lights[i];
      runtime::Light& l = lights[i + 1];
      l = runtime::Light{};
      l.on = true;
      l.units = runtime::Units::kScene;
      l.color = s.diffuse;
      l.ambient = s.ambient;
      l.specular = s.specular;
      l.ownSpecular = true;
      const Vec3 p = s.position.xyz();
      if (s.position.w == 0) {
        l.type = runtime::LightType::kDirectional;
        l.direction = length(p) > 0 ? normalize(-p) : Vec3{0, 0, -1};
      } else {
        l.type = runtime::LightType::kPositional;
        l.position = p / s.position.w;
      }
    }
  }
  show.global().background = d.background;
  const std::filesystem::path folder = scene.path.parent_path();
  if (!d.skybox.empty()) {
    show.backgroundKind() = runtime::BackgroundKind::kSkybox;
    show.backgroundImage() = resolveReferencedFile(d.skybox, folder, {}).path.string();
  } else if (!d.backgroundImage.empty()) {
    show.backgroundKind() = runtime::BackgroundKind::kImage;
    show.backgroundImage() = resolveReferencedFile(d.backgroundImage, folder, {}).path.string();
  }
  if (d.fog) {
    runtime::Fog& f = show.fog();
    f.mode = d.fog->function == SceneFogFunction::kLinear ? runtime::FogMode::kLinear
             : d.fog->function == SceneFogFunction::kExp  ? runtime::FogMode::kExp
                                                          : runtime::FogMode::kExp2;
    f.color = d.fog->color;
    f.start = d.fog->start;
    f.end = d.fog->end;
    f.density = d.fog->density;
    f.units = runtime::Units::kScene;
  }
  show.stereo().eyeSpacing = d.eyeSpacing;
  show.stereo().units = runtime::Units::kScene;
  runtime::Viewer& v = show.viewer();
  v.fromScene = true;
  v.framing = runtime::Framing::kScene;
  v.position = d.position;
  v.rotation = d.rotation;
  v.fieldOfView = d.fieldOfView;
  v.nearClip = d.nearClip;
  v.farClip = d.farClip;
  v.eyeSpacing = d.eyeSpacing;
  v.mapMin = d.mapMin;
  v.mapMax = d.mapMax;
  v.positionSpeed = d.positionChange;
  v.rotationSpeed = d.rotationChange;
  if (d.viewport) {
    v.viewportX = (*d.viewport)[0];
    v.viewportY = (*d.viewport)[1];
    v.viewportWidth = (*d.viewport)[2];
    v.viewportHeight = (*d.viewport)[3];
  }
  v.followTerrain = !scene.terrains.empty();
}

void useFitFraming(runtime::Show& show) {
  runtime::Viewer& v = show.viewer();
  v.framing = runtime::Framing::kFit;
  v.position = {0, 0, 0};
  v.rotation = {0, 0, 0};
}

// ---- Writing -------------------------------------------------------------------------------------

SceneDescription describeScene(const runtime::Show& show, const std::filesystem::path& folder) {
  SceneDescription d;
  const runtime::Viewer& v = show.viewer();
  d.position = v.position;
  d.rotation = v.rotation;
  d.fieldOfView = v.fieldOfView;
  d.nearClip = v.nearClip;
  d.farClip = v.farClip;
  d.eyeSpacing = v.eyeSpacing;
  d.mapMin = v.mapMin;
  d.mapMax = v.mapMax;
  d.positionChange = v.positionSpeed;
  d.rotationChange = v.rotationSpeed;
  if (v.viewportWidth > 0 || v.viewportHeight > 0 || v.viewportX != 0 || v.viewportY != 0) {
    d.viewport = std::array<std::int32_t, 4>{v.viewportX, v.viewportY, v.viewportWidth, v.viewportHeight};
  }
  d.background = show.global().background;
  if (show.backgroundKind() == runtime::BackgroundKind::kImage) {
    d.backgroundImage = relativeReference(show.backgroundImage(), folder);
  } else if (show.backgroundKind() == runtime::BackgroundKind::kSkybox) {
    d.skybox = relativeReference(show.backgroundImage(), folder);
  }
  const runtime::Fog& f = show.fog();
  if (f.mode != runtime::FogMode::kNone) {
    SceneFog fog;
    fog.start = f.start;
    fog.end = f.end;
    fog.density = f.density;
    fog.color = f.color;
    fog.function = f.mode == runtime::FogMode::kLinear ? SceneFogFunction::kLinear
                   : f.mode == runtime::FogMode::kExp  ? SceneFogFunction::kExp
                                                       : SceneFogFunction::kExp2;
    d.fog = fog;
  }
  runtime::Color3 ambient{0, 0, 0};
  for (std::size_t i = 0; i < show.lights().size(); ++i) {
    const runtime::Light& l = show.lights()[i];
    if (!l.on) continue;
    if (l.type == runtime::LightType::kAmbient) {
      // A scene's light 0 is the global ambient every scene has; not a light of the file.
      if (i == 0 && l.color == kSceneGlobalAmbient && l.ambient == runtime::Color3{0, 0, 0}) continue;
      ambient = {ambient.r + l.color.r + l.ambient.r, ambient.g + l.color.g + l.ambient.g,
                 ambient.b + l.color.b + l.ambient.b};
      continue;
    }
    SceneLight s;
    s.ambient = l.ambient;
    s.diffuse = l.color;
    s.specular = l.ownSpecular ? l.specular : l.color;
    if (l.type == runtime::LightType::kDirectional) {
      const Vec3 towards = -normalize(l.direction);
      s.position = {towards.x, towards.y, towards.z, 0};
    } else {
      s.position = {l.position.x, l.position.y, l.position.z, 1};
    }
    d.lights.push_back(s);
  }
  if (ambient != runtime::Color3{0, 0, 0}) {
    if (d.lights.empty()) {
      SceneLight s;
      s.diffuse = s.specular = {0, 0, 0};
      d.lights.push_back(s);
    }
    SceneLight& first = d.lights.front();
    first.ambient = {std::min(first.ambient.r + ambient.r, 1.0f), std::min(first.ambient.g + ambient.g, 1.0f),
                     std::min(first.ambient.b + ambient.b, 1.0f)};
  }
  std::vector<std::string> seen;
  for (const runtime::SceneNode& n : show.nodes()) {
    if (n.source.empty()) continue;
    const std::string ext = lowerAscii(std::filesystem::path(n.source).extension().string());
    if (ext != ".obj" && ext != ".off") continue;  // terrains come from scenes; built-ins have no file
    if (std::find(seen.begin(), seen.end(), n.source) != seen.end()) continue;
    seen.push_back(n.source);
    SceneSource s;
    s.kind = SceneSource::Kind::kModel;
    s.path = relativeReference(n.source, folder);
    d.sources.push_back(std::move(s));
  }
  return d;
}

namespace {

int byte(float c) { return static_cast<int>(std::lround(std::clamp(c, 0.0f, 1.0f) * 255.0f)); }

bool exactByte(float c) {
  const float scaled = c * 255.0f;
  return scaled >= 0 && scaled <= 255 && static_cast<float>(std::lround(scaled)) / 255.0f == c;
}

/// Colours as the thesis writes them, 0..255; a colour that no byte holds exactly is written as
/// 0..1 fractions (the reader tells them apart by the decimal point), so nothing is lost.
std::string colourText(const runtime::Color3& c) {
  if (exactByte(c.r) && exactByte(c.g) && exactByte(c.b)) {
    return fmt::format("{},{},{}", byte(c.r), byte(c.g), byte(c.b));
  }
  return fmt::format("{},{},{}", std::clamp(c.r, 0.0f, 1.0f), std::clamp(c.g, 0.0f, 1.0f), std::clamp(c.b, 0.0f, 1.0f));
}

std::string vecText(const Vec3& v) { return fmt::format("{},{},{}", v.x, v.y, v.z); }

void materialChanges(std::string& out, const SceneMaterial& from, const SceneMaterial& to) {
  if (to.emission != from.emission) out += fmt::format("emission[{}]\n", colourText(to.emission));
  if (to.ambient != from.ambient) out += fmt::format("ambient[{}]\n", colourText(to.ambient));
  if (to.diffuse != from.diffuse) out += fmt::format("diffuse[{}]\n", colourText(to.diffuse));
  if (to.specular != from.specular) out += fmt::format("specular[{}]\n", colourText(to.specular));
  if (to.shininess != from.shininess) out += fmt::format("shininess[{}]\n", to.shininess);
}

}  // namespace

std::string formatScene(const SceneDescription& s) {
  std::string out = "# Scene written by Basalt (thesis appendix C.3)\n";
  if (s.viewport) {
    const auto& vp = *s.viewport;
    out += fmt::format("viewport position[{},{}] resolution[{},{}]\n", vp[0], vp[1], vp[2], vp[3]);
  }
  out += fmt::format("projection fov[{}] nearclip[{}] farclip[{}]\n", s.fieldOfView, s.nearClip, s.farClip);
  out += fmt::format("eyespacing[{}]\n", s.eyeSpacing);
  out += fmt::format("bgcolor[{}]\n", colourText(s.background));
  if (!s.backgroundImage.empty()) out += fmt::format("background {}\n", s.backgroundImage);
  if (!s.skybox.empty()) out += fmt::format("skybox {}\n", s.skybox);
  if (s.fog) {
    const char* fn = s.fog->function == SceneFogFunction::kLinear ? "linear"
                     : s.fog->function == SceneFogFunction::kExp  ? "exp"
                                                                  : "exp2";
    out += fmt::format("fog start[{}] end[{}] density[{}] color[{}] function[{}]\n", s.fog->start, s.fog->end,
                       s.fog->density, colourText(s.fog->color), fn);
  }
  out += fmt::format("mapmin[{}]\nmapmax[{}]\n", vecText(s.mapMin), vecText(s.mapMax));
  out += fmt::format("position[{}]\nrotation[{}]\n", vecText(s.position), vecText(s.rotation));
  out += fmt::format("positionchange[{}]\nrotationchange[{}]\n", s.positionChange, s.rotationChange);
  for (const SceneLight& l : s.lights) {
    out +=
        fmt::format("light position[{},{},{},{}] ambient[{}] diffuse[{}] specular[{}]\n", l.position.x, l.position.y,
                    l.position.z, l.position.w, colourText(l.ambient), colourText(l.diffuse), colourText(l.specular));
  }
  SceneMaterial state;
  for (const SceneSource& src : s.sources) {
    materialChanges(out, state, src.material);
    state = src.material;
    switch (src.kind) {
      case SceneSource::Kind::kModel: out += fmt::format("import {}\n", src.path); break;
      case SceneSource::Kind::kDirectory: out += fmt::format("importdir {}\n", src.path); break;
      case SceneSource::Kind::kTerrain:
        out += fmt::format("terrain {} amplitude[{}] position[{}]\n", src.path, src.amplitude, vecText(src.position));
        break;
    }
  }
  materialChanges(out, state, s.finalMaterial);
  return out;
}

Result<void> writeScene(const std::filesystem::path& path, const SceneDescription& scene) {
  return writeTextFile(path, formatScene(scene));
}

}  // namespace basalt::formats
