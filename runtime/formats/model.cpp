// Models into and out of the Show: format dispatch, the scene graph of objects (parents,
// instances, placement), materials as LAVA part attributes, and the Show's scene graph back as a
// model for saving.

#include "runtime/formats/model.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <unordered_map>

#include <fmt/format.h>

#include "runtime/formats/obj_internal.h"

namespace basalt::formats {

// ---- Objects ----------------------------------------------------------------------------------

Mat4 ModelObject::localTransform() const {
  return Mat4::translation(position) * Mat4::rotationX(rotation.x) * Mat4::rotationY(rotation.y) *
         Mat4::rotationZ(rotation.z) * Mat4::scaling(scale);
}

namespace {

bool sameMeshContent(const runtime::Mesh* a, const runtime::Mesh* b) {
  if (a == b) return true;
  if (!a || !b) return false;
  return a->positions == b->positions && a->normals == b->normals && a->texcoords == b->texcoords &&
         a->colors == b->colors && a->triangles == b->triangles && a->edges == b->edges && a->lines == b->lines &&
         a->points == b->points && a->facetSizes == b->facetSizes && a->parts == b->parts &&
         a->materials == b->materials;
}

}  // namespace

bool operator==(const ModelObject& a, const ModelObject& b) {
  return a.name == b.name && a.parent == b.parent && a.instanceOf == b.instanceOf && a.position == b.position &&
         a.rotation == b.rotation && a.scale == b.scale && a.colorMap == b.colorMap &&
         a.reflectionMap == b.reflectionMap && a.bumpMap == b.bumpMap && sameMeshContent(a.mesh.get(), b.mesh.get());
}

ModelCounts countModel(const LoadedModel& model) {
  ModelCounts c;
  c.objects = model.objects.size();
  std::vector<const runtime::Mesh*> seen;
  std::vector<std::string> materialNames;
  for (const ModelObject& o : model.objects) {
    const runtime::Mesh* m = o.mesh.get();
    if (!m || std::find(seen.begin(), seen.end(), m) != seen.end()) continue;
    seen.push_back(m);
    c.vertices += m->positions.size();
    c.triangles += m->triangleCount();
    c.facets += m->facetSizes.empty() ? m->triangleCount() : m->facetSizes.size();
    c.lineSegments += m->lines.size() / 2;
    c.points += m->points.size();
    c.parts += m->parts.size();
    for (const runtime::Material& mat : m->materials) {
      if (std::find(materialNames.begin(), materialNames.end(), mat.name) == materialNames.end()) {
        materialNames.push_back(mat.name);
      }
    }
  }
  c.materials = materialNames.size();
  return c;
}

// ---- Loading ----------------------------------------------------------------------------------

namespace {

enum class Sniffed { kObj, kOff, kUnknown };

/// Guesses the format from the first statement of the text.
Sniffed sniff(std::string_view text) {
  LineReader lines(text);
  int looked = 0;
  while (auto raw = lines.next()) {
    if (++looked > 200) break;
    std::string_view line = *raw;
    if (const auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    const auto tokens = splitBlanks(line);
    if (tokens.empty()) continue;
    const std::string_view first = tokens[0];
    if (first.size() >= 3 && first.substr(first.size() - 3) == "OFF") return Sniffed::kOff;
    std::int64_t probe = 0;
    if (parseInt(first, probe) && tokens.size() >= 2 && tokens.size() <= 3) {
      bool allCounts = true;
      for (std::string_view t : tokens) allCounts = allCounts && parseInt(t, probe);
      if (allCounts) return Sniffed::kOff;
    }
    static constexpr std::string_view kObjKeywords[] = {
        "v", "vt", "vn", "vc", "f", "l", "p", "o", "g", "s", "usemtl", "mtllib", "parent", "instanceof", "usemap"};
    for (std::string_view k : kObjKeywords) {
      if (first == k) return Sniffed::kObj;
    }
    return Sniffed::kUnknown;
  }
  return Sniffed::kUnknown;
}

}  // namespace

Result<LoadedModel> loadModel(const std::filesystem::path& path, const LoadOptions& options) {
  // OBJ files are read a chunk at a time (the text is never whole in memory); UTF-16 text, OFF
  // content in a .obj file, and other names go through the whole-file path below.
  if (lowerAscii(path.extension().string()) == ".obj") {
    bool fallback = false;
    auto model = readObjStreamed(path, options, fallback);
    if (!fallback) return model;
  }
  auto bytes = readFileBytes(path, options.limits.maxFileBytes);
  if (!bytes) return std::unexpected(bytes.error());
  Diagnostics decoding(path.string(), options.limits.maxWarnings, options.logWarnings);
  auto text = decodeText(std::move(*bytes), decoding);
  if (!text) return std::unexpected(text.error());
  const std::string ext = lowerAscii(path.extension().string());
  Sniffed format = ext == ".obj" ? Sniffed::kObj : ext == ".off" ? Sniffed::kOff : Sniffed::kUnknown;
  const Sniffed content = sniff(*text);
  if (format == Sniffed::kUnknown) {
    format = content;
    if (format == Sniffed::kUnknown) {
      return fail(Errc::kUnsupported,
                  "this is not a model Basalt reads (Wavefront OBJ or OFF, recognised by the extension .obj or .off "
                  "or by their first statement)",
                  path.string());
    }
  } else if (format == Sniffed::kObj && content == Sniffed::kOff) {
    decoding.warn(0, 0, "the file is named .obj but holds OFF; it is read as OFF");
    format = Sniffed::kOff;
  }
  Result<LoadedModel> model = format == Sniffed::kOff ? readOffFile(std::move(*text), path, options)
                                                      : readObjFile(std::move(*text), path, options);
  if (!model) return model;
  std::vector<Diagnostic> first = decoding.finish();
  if (!first.empty()) model->warnings.insert(model->warnings.begin(), first.begin(), first.end());
  return model;
}

// ---- Into the Show ----------------------------------------------------------------------------

namespace {

float luminance(const runtime::Color3& c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }
float clamp01(float v) { return std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f; }
runtime::Color3 clamp01(const runtime::Color3& c) { return {clamp01(c.r), clamp01(c.g), clamp01(c.b)}; }

}  // namespace

void applyMaterial(runtime::Show& show, runtime::PartId part, const runtime::Material& material) {
  using runtime::AttrId;
  using runtime::PartStyle;
  const runtime::Color3 colour = clamp01(material.diffuse);
  const float diffuseLum = luminance(colour);
  // XGL multiplies the ambient light by ka * Od; OpenGL-style materials give Ka directly.
  const float ka = diffuseLum > 0 ? clamp01(luminance(material.ambient) / diffuseLum) : 0.0f;
  const float ks = clamp01(std::max({material.specular.r, material.specular.g, material.specular.b}));
  const runtime::Color3 specColour =
      ks > 0 ? clamp01(runtime::Color3{material.specular.r / ks, material.specular.g / ks, material.specular.b / ks})
             : runtime::Color3{1, 1, 1};
  show.editPartStyle(part, AttrId::kFrontColor, [&](PartStyle& s) { s.front.color = colour; });
  show.editPartStyle(part, AttrId::kLinesColor, [&](PartStyle& s) { s.lines.color = colour; });
  show.editPartStyle(part, AttrId::kMarkersColor, [&](PartStyle& s) { s.markers.color = colour; });
  show.editPartStyle(part, AttrId::kFrontDiffuse, [&](PartStyle& s) { s.front.diffuse = 1.0f; });
  show.editPartStyle(part, AttrId::kFrontAmbient, [&](PartStyle& s) { s.front.ambient = ka; });
  show.editPartStyle(part, AttrId::kFrontSpecular, [&](PartStyle& s) { s.front.specular = ks; });
  show.editPartStyle(part, AttrId::kFrontSpecularColor, [&](PartStyle& s) { s.front.specularColor = specColour; });
  if (material.shininess > 0 && std::isfinite(material.shininess)) {
    show.editPartStyle(part, AttrId::kFrontSpecularPower,
                       [&](PartStyle& s) { s.front.specularPower = std::min(material.shininess, 1000.0f); });
  }
  if (material.opacity < 1.0f) {
    const float transparency = 1.0f - clamp01(material.opacity);
    show.editPartStyle(part, AttrId::kFrontTranspMethod,
                       [&](PartStyle& s) { s.front.transparencyMethod = runtime::TransparencyMethod::kBlended; });
    show.editPartStyle(part, AttrId::kFrontTransparency, [&](PartStyle& s) { s.front.transparency = transparency; });
  }
}

void applySceneMaterial(runtime::Show& show, runtime::PartId part, const runtime::Material& material) {
  using runtime::AttrId;
  using runtime::PartStyle;
  applyMaterial(show, part, material);
  const runtime::Color3 ambient = clamp01(material.ambient);
  const runtime::Color3 emission = clamp01(material.emissive);
  show.editPartStyle(part, AttrId::kFrontAmbient, [&](PartStyle& s) { s.front.ambient = 1.0f; });
  show.editPartStyle(part, AttrId::kFrontAmbientColor, [&](PartStyle& s) { s.front.ambientColor = {true, ambient}; });
  show.editPartStyle(part, AttrId::kFrontEmission, [&](PartStyle& s) { s.front.emission = emission; });
  // OpenGL's shininess runs 0..128; 0 is a highlight everywhere, as (R.E)^0 is.
  const float shininess = std::isfinite(material.shininess) ? std::clamp(material.shininess, 0.0f, 128.0f) : 0.0f;
  show.editPartStyle(part, AttrId::kFrontSpecularPower, [&](PartStyle& s) { s.front.specularPower = shininess; });
}

namespace {

struct Entry {
  const LoadedModel* model = nullptr;
  const ModelObject* object = nullptr;
  const runtime::Material* materialState = nullptr;
  bool sceneMaterial = false;
  std::string instanceOf;         // the object whose geometry an instance shares ("" = its own)
  std::int32_t parentEntry = -1;  // among entries
  std::int32_t parentNode = -1;   // a node already in the Show
  std::shared_ptr<const runtime::Mesh> mesh;
  std::uint8_t state = 0;  // 0 new, 1 being placed, 2 placed
  runtime::NodeId node = 0;
};

std::string whereOf(const Entry& e) {
  const std::string file = e.model->path.empty() ? std::string("model") : e.model->path.string();
  return e.object->line ? fmt::format("{}:{}", file, e.object->line) : file;
}

}  // namespace

std::vector<runtime::NodeId> addModels(runtime::Show& show, const std::vector<ModelImport>& imports,
                                       std::vector<Diagnostic>& warnings) {
  std::vector<Entry> entries;
  for (const ModelImport& import : imports) {
    if (!import.model) continue;
    for (const ModelObject& o : import.model->objects) {
      Entry e;
      e.model = import.model;
      e.object = &o;
      e.materialState = import.materialState;
      e.sceneMaterial = import.sceneMaterial;
      e.mesh = o.mesh;
      entries.push_back(std::move(e));
    }
  }
  std::unordered_map<std::string, std::int32_t> byName;
  for (std::size_t i = 0; i < entries.size(); ++i) {
    auto [it, inserted] = byName.emplace(entries[i].object->name, static_cast<std::int32_t>(i));
    if (!inserted) {
      warnings.push_back({whereOf(entries[i]),
                          fmt::format("another object is already called '{}'; parents and instances naming it mean "
                                      "the first",
                                      entries[i].object->name)});
    }
  }
  const auto note = [&](const Entry& e, std::string message) {
    warnings.push_back({whereOf(e), message});
    log::warn(kLogFormats, "{}: {}", whereOf(e), message);
  };
  // Instances share the geometry of the object they name (following chains of instances).
  for (Entry& e : entries) {
    const std::string* target = &e.object->instanceOf;
    std::size_t hops = 0;
    while (!target->empty() && !e.mesh) {
      auto it = byName.find(*target);
      if (it != byName.end()) {
        const Entry& source = entries[static_cast<std::size_t>(it->second)];
        if (source.object->mesh) {
          e.mesh = source.object->mesh;
          e.instanceOf = source.object->name;
          break;
        }
        target = &source.object->instanceOf;
      } else if (auto node = show.findNode(*target); node && show.nodes()[*node].mesh) {
        e.mesh = show.nodes()[*node].mesh;
        e.instanceOf = *target;
        break;
      } else {
        note(e, fmt::format("'{}' is an instance of '{}', which is not loaded; it has no geometry", e.object->name,
                            *target));
        break;
      }
      if (++hops > entries.size()) {
        note(e, fmt::format("'{}' is an instance of an instance in a circle; it has no geometry", e.object->name));
        break;
      }
    }
  }
  // Parents: another object loaded now, or a node already in the Show.
  for (Entry& e : entries) {
    const std::string& parent = e.object->parent;
    if (parent.empty()) continue;
    auto it = byName.find(parent);
    if (it != byName.end()) {
      if (&entries[static_cast<std::size_t>(it->second)] == &e) {
        note(e, fmt::format("'{}' names itself as its parent; it is placed at the root", parent));
      } else {
        e.parentEntry = it->second;
      }
    } else if (auto node = show.findNode(parent)) {
      e.parentNode = static_cast<std::int32_t>(*node);
    } else {
      note(e, fmt::format("the parent '{}' of '{}' is not loaded; '{}' is placed at the root", parent, e.object->name,
                          e.object->name));
    }
  }
  // Place parents before children, breaking circles.
  std::vector<runtime::NodeId> ids(entries.size(), 0);
  std::vector<std::size_t> stack;
  const auto place = [&](std::size_t start) {
    stack.clear();
    stack.push_back(start);
    while (!stack.empty()) {
      Entry& e = entries[stack.back()];
      if (e.state == 2) {
        stack.pop_back();
        continue;
      }
      if (e.state == 0 && e.parentEntry >= 0) {
        Entry& p = entries[static_cast<std::size_t>(e.parentEntry)];
        if (p.state == 1) {
          note(e, fmt::format("'{}' and its parents form a circle; '{}' is placed at the root", e.object->name,
                              e.object->name));
          e.parentEntry = -1;
        } else if (p.state == 0) {
          e.state = 1;
          stack.push_back(static_cast<std::size_t>(e.parentEntry));
          continue;
        }
      }
      runtime::SceneNode node;
      node.name = e.object->name;
      node.parent = e.parentEntry >= 0
                        ? static_cast<std::int32_t>(entries[static_cast<std::size_t>(e.parentEntry)].node)
                        : e.parentNode;
      node.local = e.object->localTransform();
      node.mesh = e.mesh;
      if (!e.instanceOf.empty() && e.mesh) {
        for (const runtime::MeshPart& mp : e.mesh->parts) {
          node.partNames.push_back(mp.name == e.instanceOf ? e.object->name : e.object->name + "/" + mp.name);
        }
      }
      node.colorMap = e.object->colorMap;
      node.reflectionMap = e.object->reflectionMap;
      node.bumpMap = e.object->bumpMap;
      node.source = e.model->path.string();
      e.node = show.addNode(std::move(node));
      e.state = 2;
      stack.pop_back();
    }
  };
  for (std::size_t i = 0; i < entries.size(); ++i) place(i);
  // Textures and materials of the parts.
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const Entry& e = entries[i];
    ids[i] = e.node;
    const runtime::SceneNode& node = show.nodes()[e.node];
    if (!node.mesh) continue;
    for (std::size_t k = 0; k < node.mesh->parts.size() && k < node.partIds.size(); ++k) {
      const runtime::MeshPart& part = node.mesh->parts[k];
      const runtime::PartId id = node.partIds[k];
      const runtime::Material* material =
          part.material >= 0 && static_cast<std::size_t>(part.material) < node.mesh->materials.size()
              ? &node.mesh->materials[static_cast<std::size_t>(part.material)]
              : nullptr;
      if (material && !material->diffuseMap.empty()) {
        show.setPartTexture(id, material->diffuseMap);
      } else if (!node.colorMap.empty()) {
        show.setPartTexture(id, node.colorMap);
      }
      if (material) {
        applyMaterial(show, id, *material);
      } else if (e.materialState && e.sceneMaterial) {
        applySceneMaterial(show, id, *e.materialState);
      } else if (e.materialState) {
        applyMaterial(show, id, *e.materialState);
      }
    }
  }
  return ids;
}

Result<void> replaceObject(runtime::Show& show, const LoadedModel& model) {
  bool anything = false;
  for (const ModelObject& o : model.objects) anything = anything || o.mesh || !o.instanceOf.empty();
  if (!anything) {
    return fail(Errc::kInvalidArgument, "the model has nothing to show; the current object is kept",
                model.path.string());
  }
  show.clear();
  std::vector<Diagnostic> warnings;
  addModels(show, {ModelImport{&model, nullptr}}, warnings);
  return {};
}

// ---- Out of the Show --------------------------------------------------------------------------

namespace {

/// Splits a transform into translation, rotation (M = T Rx Ry Rz S) and scale.
void decompose(const Mat4& m, Vec3& position, Vec3& rotationDegrees, Vec3& scale) {
  position = {m(0, 3), m(1, 3), m(2, 3)};
  Vec3 c0{m(0, 0), m(1, 0), m(2, 0)}, c1{m(0, 1), m(1, 1), m(2, 1)}, c2{m(0, 2), m(1, 2), m(2, 2)};
  scale = {length(c0), length(c1), length(c2)};
  if (dot(cross(c0, c1), c2) < 0) scale.x = -scale.x;  // a mirror: put it on X
  const auto safe = [](const Vec3& v, float s) { return s != 0 ? v / s : v; };
  c0 = safe(c0, scale.x);
  c1 = safe(c1, scale.y);
  c2 = safe(c2, scale.z);
  // R = Rx Ry Rz: R(0,2) = sin y, R(1,2) = -sin x cos y, R(2,2) = cos x cos y,
  // R(0,1) = -cos y sin z, R(0,0) = cos y cos z.
  const float r02 = std::clamp(c2.x, -1.0f, 1.0f);
  const float y = std::asin(r02);
  float x = 0, z = 0;
  if (std::fabs(r02) < 0.999999f) {
    x = std::atan2(-c2.y, c2.z);
    z = std::atan2(-c1.x, c0.x);
  } else {
    // Gimbal lock: only x + z (or x - z) is defined; put it all on x.
    x = std::atan2(c0.y * r02, c1.y);
  }
  constexpr float kDeg = 180.0f / std::numbers::pi_v<float>;
  rotationDegrees = {x * kDeg, y * kDeg, z * kDeg};
  const auto tidy = [](float v) { return std::fabs(v) < 1e-5f ? 0.0f : v; };
  rotationDegrees = {tidy(rotationDegrees.x), tidy(rotationDegrees.y), tidy(rotationDegrees.z)};
}

}  // namespace

LoadedModel modelFromShow(const runtime::Show& show) {
  LoadedModel model;
  model.extended = true;
  const auto& nodes = show.nodes();
  std::vector<std::string> names(nodes.size());
  std::map<std::string, int> used;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    std::string name = nodes[i].name.empty() ? fmt::format("object{}", i + 1) : nodes[i].name;
    int& count = used[name];
    if (++count > 1) name = fmt::format("{}.{}", name, count);
    names[i] = name;
  }
  std::map<const runtime::Mesh*, std::size_t> firstUser;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const runtime::SceneNode& n = nodes[i];
    ModelObject o;
    o.name = names[i];
    if (n.parent >= 0 && static_cast<std::size_t>(n.parent) < nodes.size()) {
      o.parent = names[static_cast<std::size_t>(n.parent)];
    }
    decompose(n.local, o.position, o.rotation, o.scale);
    o.colorMap = n.colorMap;
    o.reflectionMap = n.reflectionMap;
    o.bumpMap = n.bumpMap;
    if (n.mesh) {
      auto [it, first] = firstUser.emplace(n.mesh.get(), i);
      if (first) {
        o.mesh = n.mesh;
      } else {
        o.instanceOf = names[it->second];
      }
    }
    model.objects.push_back(std::move(o));
  }
  return model;
}

Result<void> saveObject(const runtime::Show& show, const std::filesystem::path& path, bool extended) {
  LoadedModel model = modelFromShow(show);
  if (model.objects.empty()) return fail(Errc::kInvalidArgument, "there is no object to save", path.string());
  model.path = path;
  ObjWriteOptions options;
  options.extended = extended;
  return writeObj(path, model, options);
}

}  // namespace basalt::formats
