// Writing models: Wavefront OBJ (LAVA "Save Object": everything in scene coordinates) and the
// thesis' Extended OBJ (objects in their own coordinates with parent, instanceof, position,
// rotation, scale and usemap), each with an MTL library when there are materials. Numbers are
// written in their shortest exact form, so a written file reads back to the same meshes.

#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>

#include <fmt/format.h>

#include "runtime/formats/model.h"
#include "runtime/formats/mtl.h"

namespace basalt::formats {

namespace {

constexpr std::string_view kDefaultMaterial = "basalt_default";

void appendFloat(std::string& out, float v) { fmt::format_to(std::back_inserter(out), "{}", v); }

bool exactByte(float v) {
  const float scaled = v * 255.0f;
  return scaled >= 0 && scaled <= 255 && std::nearbyint(scaled) == scaled &&
         static_cast<float>(static_cast<int>(scaled)) / 255.0f == v;
}

/// Writes one Extended OBJ vertex colour: 0..255 integers when exact, otherwise fractions, with a
/// '.' or an exponent so that the reader takes them as 0..1.
void appendVertexColour(std::string& out, const Vec4& c) {
  if (exactByte(c.x) && exactByte(c.y) && exactByte(c.z) && exactByte(c.w)) {
    fmt::format_to(std::back_inserter(out), "vc {} {} {} {}\n", std::lround(c.x * 255.0f), std::lround(c.y * 255.0f),
                   std::lround(c.z * 255.0f), std::lround(c.w * 255.0f));
    return;
  }
  const std::size_t start = out.size();
  fmt::format_to(std::back_inserter(out), "vc {} {} {} {}", c.x, c.y, c.z, c.w);
  if (std::string_view(out).substr(start).find_first_of(".eE") == std::string_view::npos) out += ".0";
  out += '\n';
}

struct Writer {
  std::string out;
  /// Extended OBJ: colours go on 'vc' lines, one for every vertex of the file. The reader gives
  /// the n-th 'vc' to the n-th vertex of the whole file, so either every mesh writes them or none.
  bool vertexColourLines = false;
  std::size_t positionsWritten = 0;
  std::size_t texcoordsWritten = 0;
  std::size_t normalsWritten = 0;
  std::vector<runtime::Material> materials;  // the library, unique by name
  bool needDefaultMaterial = false;

  /// The name to write for a mesh material, adding it to the library.
  std::string materialName(const runtime::Material& m) {
    for (const runtime::Material& existing : materials) {
      if (existing.name == m.name) return m.name;
    }
    materials.push_back(m);
    return m.name;
  }

  /// Writes one mesh; `transform` (plain OBJ) moves it into scene coordinates.
  void mesh(const runtime::Mesh& m, const Mat4* transform, bool extended) {
    const std::size_t count = m.positions.size();
    const bool colours = m.colors.size() == count && count > 0;
    const bool texcoords = m.texcoords.size() == count && count > 0;
    const bool normals = m.normals.size() == count && count > 0;
    bool opaque = true;
    if (colours) {
      for (const Vec4& c : m.colors) opaque = opaque && c.w == 1.0f;
    }
    const bool writeVc = extended && vertexColourLines;
    const Mat4 normalMatrix = transform ? transform->inverted().transposed() : Mat4{};
    for (std::size_t i = 0; i < count; ++i) {
      const Vec3 p = transform ? transform->transformPoint(m.positions[i]) : m.positions[i];
      out += "v ";
      appendFloat(out, p.x);
      out += ' ';
      appendFloat(out, p.y);
      out += ' ';
      appendFloat(out, p.z);
      if (colours && !writeVc) {
        const Vec4& c = m.colors[i];
        fmt::format_to(std::back_inserter(out), " {} {} {}", c.x, c.y, c.z);
        if (!opaque) fmt::format_to(std::back_inserter(out), " {}", c.w);
      }
      out += '\n';
    }
    if (writeVc) {
      for (std::size_t i = 0; i < count; ++i) appendVertexColour(out, colours ? m.colors[i] : Vec4{1, 1, 1, 1});
    }
    if (texcoords) {
      for (const Vec2& t : m.texcoords) fmt::format_to(std::back_inserter(out), "vt {} {}\n", t.x, t.y);
    }
    if (normals) {
      for (const Vec3& n0 : m.normals) {
        const Vec3 n = transform ? normalize(normalMatrix.transformDirection(n0)) : n0;
        fmt::format_to(std::back_inserter(out), "vn {} {} {}\n", n.x, n.y, n.z);
      }
    }
    const std::size_t vBase = positionsWritten + 1, tBase = texcoordsWritten + 1, nBase = normalsWritten + 1;
    positionsWritten += count;
    if (texcoords) texcoordsWritten += count;
    if (normals) normalsWritten += count;
    const auto corner = [&](std::uint32_t i, bool withNormal) {
      fmt::format_to(std::back_inserter(out), " {}", vBase + i);
      if (texcoords && withNormal && normals) {
        fmt::format_to(std::back_inserter(out), "/{}/{}", tBase + i, nBase + i);
      } else if (texcoords) {
        fmt::format_to(std::back_inserter(out), "/{}", tBase + i);
      } else if (withNormal && normals) {
        fmt::format_to(std::back_inserter(out), "//{}", nBase + i);
      }
    };
    bool materialSet = false;
    std::size_t facet = 0, edge = 0;
    for (const runtime::MeshPart& part : m.parts) {
      fmt::format_to(std::back_inserter(out), "g {}\n", part.name);
      if (part.material >= 0 && static_cast<std::size_t>(part.material) < m.materials.size()) {
        fmt::format_to(std::back_inserter(out), "usemtl {}\n",
                       materialName(m.materials[static_cast<std::size_t>(part.material)]));
        materialSet = true;
      } else if (materialSet) {
        // OBJ has no "no material": a part without one after parts with one gets a default.
        fmt::format_to(std::back_inserter(out), "usemtl {}\n", kDefaultMaterial);
        needDefaultMaterial = true;
      }
      if (!m.facetSizes.empty()) {
        facet = part.firstFacet;
        edge = part.firstEdgeIndex;
        for (std::uint32_t f = 0; f < part.facetCount && facet < m.facetSizes.size(); ++f, ++facet) {
          out += 'f';
          const std::uint32_t n = m.facetSizes[facet];
          for (std::size_t k = 0; k < n && edge + 2 * k < m.edges.size(); ++k) corner(m.edges[edge + 2 * k], true);
          edge += 2 * std::size_t{n};
          out += '\n';
        }
      } else {
        for (std::uint32_t k = 0; k + 2 < part.triangleIndexCount; k += 3) {
          out += 'f';
          for (std::uint32_t c = 0; c < 3; ++c) corner(m.triangles[part.firstTriangleIndex + k + c], true);
          out += '\n';
        }
      }
      for (std::uint32_t k = 0; k + 1 < part.lineIndexCount; k += 2) {
        out += 'l';
        corner(m.lines[part.firstLineIndex + k], false);
        corner(m.lines[part.firstLineIndex + k + 1], false);
        out += '\n';
      }
      for (std::uint32_t k = 0; k < part.pointIndexCount; ++k) {
        out += 'p';
        corner(m.points[part.firstPointIndex + k], false);
        out += '\n';
      }
    }
  }
};

const ModelObject* findObject(const LoadedModel& model, const std::string& name) {
  for (const ModelObject& o : model.objects) {
    if (o.name == name) return &o;
  }
  return nullptr;
}

Mat4 worldTransform(const LoadedModel& model, const ModelObject& object) {
  Mat4 m = object.localTransform();
  const ModelObject* o = &object;
  for (std::size_t hops = 0; !o->parent.empty() && hops < model.objects.size(); ++hops) {
    o = findObject(model, o->parent);
    if (!o) break;
    m = o->localTransform() * m;
  }
  return m;
}

const runtime::Mesh* meshOf(const LoadedModel& model, const ModelObject& object) {
  const ModelObject* o = &object;
  for (std::size_t hops = 0; o && hops <= model.objects.size(); ++hops) {
    if (o->mesh) return o->mesh.get();
    if (o->instanceOf.empty()) return nullptr;
    o = findObject(model, o->instanceOf);
  }
  return nullptr;
}

}  // namespace

std::string formatObj(const LoadedModel& model, const std::filesystem::path& folder, const ObjWriteOptions& options,
                      const std::string& mtlName, std::string& mtlText) {
  Writer w;
  if (options.extended) {
    // Translucent vertex colours anywhere need 'vc' lines (a 'v' line carries r g b only).
    for (const ModelObject& o : model.objects) {
      if (!o.mesh || !o.instanceOf.empty()) continue;
      for (const Vec4& c : o.mesh->colors) w.vertexColourLines = w.vertexColourLines || c.w != 1.0f;
    }
  }
  std::string body;
  for (const ModelObject& o : model.objects) {
    w.out.clear();
    fmt::format_to(std::back_inserter(w.out), "o {}\n", o.name);
    if (options.extended) {
      if (!o.parent.empty()) fmt::format_to(std::back_inserter(w.out), "parent {}\n", o.parent);
      if (!o.instanceOf.empty()) fmt::format_to(std::back_inserter(w.out), "instanceof {}\n", o.instanceOf);
      if (o.position != Vec3{0, 0, 0}) {
        fmt::format_to(std::back_inserter(w.out), "position {} {} {}\n", o.position.x, o.position.y, o.position.z);
      }
      if (o.rotation != Vec3{0, 0, 0}) {
        fmt::format_to(std::back_inserter(w.out), "rotation {} {} {}\n", o.rotation.x, o.rotation.y, o.rotation.z);
      }
      if (o.scale != Vec3{1, 1, 1}) {
        if (o.scale.x == o.scale.y && o.scale.y == o.scale.z) {
          fmt::format_to(std::back_inserter(w.out), "scale {}\n", o.scale.x);
        } else {
          fmt::format_to(std::back_inserter(w.out), "scale {} {} {}\n", o.scale.x, o.scale.y, o.scale.z);
        }
      }
      if (!o.colorMap.empty()) {
        fmt::format_to(std::back_inserter(w.out), "usemap {} color\n", relativeReference(o.colorMap, folder));
      }
      if (!o.reflectionMap.empty()) {
        fmt::format_to(std::back_inserter(w.out), "usemap {} reflect\n", relativeReference(o.reflectionMap, folder));
      }
      if (!o.bumpMap.empty()) {
        fmt::format_to(std::back_inserter(w.out), "usemap {} bump\n", relativeReference(o.bumpMap, folder));
      }
      if (o.mesh && o.instanceOf.empty()) w.mesh(*o.mesh, nullptr, true);
    } else if (const runtime::Mesh* mesh = meshOf(model, o)) {
      const Mat4 world = worldTransform(model, o);
      w.mesh(*mesh, world == Mat4{} ? nullptr : &world, false);
    }
    body += w.out;
  }
  std::string header = options.extended ? "# Extended OBJ written by Basalt\n" : "# Wavefront OBJ written by Basalt\n";
  mtlText.clear();
  if (!w.materials.empty() || w.needDefaultMaterial) {
    if (w.needDefaultMaterial) {
      runtime::Material m;
      m.name = kDefaultMaterial;
      w.materials.push_back(m);
    }
    mtlText = formatMtl(w.materials, folder);
    header += fmt::format("mtllib {}\n", mtlName);
  }
  return header + body;
}

Result<void> writeTextFile(const std::filesystem::path& path, std::string_view text) {
  const std::filesystem::path folder = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec) {
    return fail(Errc::kIo,
                fmt::format("cannot create the folder {}: {}; choose a writable folder", folder.string(), ec.message()),
                path.string());
  }
  const std::filesystem::path temporary = folder / fmt::format(".{}.{}.partial", path.filename().string(), ::getpid());
  {
    struct Closer {
      void operator()(std::FILE* f) const { std::fclose(f); }
    };
    std::unique_ptr<std::FILE, Closer> file(std::fopen(temporary.c_str(), "wb"));
    if (!file) {
      return fail(Errc::kIo, systemErrorText("cannot create the file", errno), path.string());
    }
    if (std::fwrite(text.data(), 1, text.size(), file.get()) != text.size() || std::fflush(file.get()) != 0) {
      const int err = errno;
      file.reset();
      std::filesystem::remove(temporary, ec);
      return fail(Errc::kIo, systemErrorText("cannot write the file", err), path.string());
    }
  }
  std::filesystem::rename(temporary, path, ec);
  if (ec) {
    std::filesystem::remove(temporary, ec);
    return fail(Errc::kIo, fmt::format("cannot move the file into place: {}", ec.message()), path.string());
  }
  return {};
}

Result<void> writeObj(const std::filesystem::path& path, const LoadedModel& model, const ObjWriteOptions& options) {
  const std::filesystem::path folder = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  std::string mtlName = options.materialLibrary.empty() ? path.stem().string() + ".mtl" : options.materialLibrary;
  std::string mtlText;
  const std::string objText = formatObj(model, folder, options, mtlName, mtlText);
  if (!mtlText.empty()) {
    if (auto r = writeTextFile(folder / mtlName, mtlText); !r) return r;
  }
  return writeTextFile(path, objText);
}

}  // namespace basalt::formats
