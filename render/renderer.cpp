#include "render/renderer.h"

#include <array>
#include <cmath>
#include <cstddef>

#include "embedded/render_shaders.h"
#include "runtime/log.h"

namespace basalt::render {

BASALT_LOG_CATEGORY(Render, "render");

using runtime::FaceCulling;
using runtime::Illumination;
using runtime::PartStyle;
using runtime::PrimType;
using runtime::Show;

struct Renderer::GpuMesh {
  std::weak_ptr<const runtime::Mesh> source;
  gl::VertexArray vao;
  gl::Buffer positions;
  gl::Buffer normals;
  gl::Buffer colors;
  gl::Buffer indices;          // triangles, then edges, then lines, then points
  std::size_t edgeOffset = 0;  // in indices
  std::size_t lineOffset = 0;
  std::size_t pointOffset = 0;
  bool hasColors = false;
};

struct Renderer::ColorUniforms {
  GLint model, viewProjection, pointSize, color;
};

namespace {

struct SurfaceUniforms {
  GLint color, specularColor, ka, kd, ks, power, components, alpha;
};

void setSurface(const SurfaceUniforms& u, const runtime::SurfaceAttributes& s) {
  glUniform3f(u.color, s.color.r, s.color.g, s.color.b);
  glUniform3f(u.specularColor, s.specularColor.r, s.specularColor.g, s.specularColor.b);
  glUniform1f(u.ka, s.ambient);
  glUniform1f(u.kd, s.diffuse);
  glUniform1f(u.ks, s.specular);
  glUniform1f(u.power, s.specularPower);
  glUniform1i(u.components, s.lightComponents);
  const float alpha = s.transparencyMethod == runtime::TransparencyMethod::kNone ? 1.0f : 1.0f - s.transparency;
  glUniform1f(u.alpha, alpha);
}

std::array<float, 9> normalMatrix(const Mat4& model) {
  const Mat4 n = model.inverted().transposed();
  return {n(0, 0), n(1, 0), n(2, 0), n(0, 1), n(1, 1), n(2, 1), n(0, 2), n(1, 2), n(2, 2)};
}

template <typename T>
void uploadArray(gl::Buffer& buffer, GLenum target, const std::vector<T>& data) {
  buffer = gl::Buffer::create();
  glBindBuffer(target, buffer.id());
  glBufferData(target, static_cast<GLsizeiptr>(data.size() * sizeof(T)), data.data(), GL_STATIC_DRAW);
}

}  // namespace

struct Renderer::LitUniforms {
  GLint model, viewProjection, normalMatrix, eye, lit, useVertexColor, flat, lightCount;
  SurfaceUniforms front, back;
  GLint lightColor, lightPosition, lightDirection, lightSpot;
};

Renderer::Renderer() = default;

Renderer::~Renderer() = default;

Result<std::unique_ptr<Renderer>> Renderer::create() {
  std::unique_ptr<Renderer> r(new Renderer);
  auto lit = gl::buildProgram(shaders::kLitVert, shaders::kLitFrag, "lit");
  if (!lit) return std::unexpected(lit.error());
  auto color = gl::buildProgram(shaders::kColorVert, shaders::kColorFrag, "color");
  if (!color) return std::unexpected(color.error());
  r->lit_ = std::move(*lit);
  r->color_ = std::move(*color);

  const GLuint p = r->lit_.id();
  auto at = [p](const char* name) { return glGetUniformLocation(p, name); };
  auto surface = [&](const char* prefix) {
    auto field = [&](const char* f) { return at(fmt::format("{}.{}", prefix, f).c_str()); };
    return SurfaceUniforms{field("color"), field("specularColor"), field("ka"),         field("kd"),
                           field("ks"),    field("power"),         field("components"), field("alpha")};
  };
  r->litUniforms_ = std::make_unique<LitUniforms>(
      LitUniforms{at("uModel"), at("uViewProjection"), at("uNormalMatrix"), at("uEye"), at("uLit"),
                  at("uUseVertexColor"), at("uFlat"), at("uLightCount"), surface("uFront"), surface("uBack"),
                  at("uLightColor"), at("uLightPosition"), at("uLightDirection"), at("uLightSpot")});
  const GLuint c = r->color_.id();
  r->colorUniforms_ = std::make_unique<ColorUniforms>(
      ColorUniforms{glGetUniformLocation(c, "uModel"), glGetUniformLocation(c, "uViewProjection"),
                    glGetUniformLocation(c, "uPointSize"), glGetUniformLocation(c, "uColor")});
  if (const GLenum e = gl::drainErrors(); e != GL_NO_ERROR) {
    return fail(Errc::kInternal, fmt::format("setting up the renderer: {}", gl::errorName(e)));
  }
  return r;
}

Renderer::GpuMesh& Renderer::upload(const std::shared_ptr<const runtime::Mesh>& mesh) {
  auto it = meshes_.find(mesh->id());
  if (it != meshes_.end()) return *it->second;

  auto gpu = std::make_unique<GpuMesh>();
  gpu->source = mesh;
  gpu->vao = gl::VertexArray::create();
  glBindVertexArray(gpu->vao.id());
  uploadArray(gpu->positions, GL_ARRAY_BUFFER, mesh->positions);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Vec3), nullptr);
  if (mesh->normals.size() == mesh->positions.size()) {
    uploadArray(gpu->normals, GL_ARRAY_BUFFER, mesh->normals);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(Vec3), nullptr);
  } else {
    glVertexAttrib3f(1, 0, 0, 1);
  }
  if (mesh->colors.size() == mesh->positions.size()) {
    uploadArray(gpu->colors, GL_ARRAY_BUFFER, mesh->colors);
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, sizeof(Vec4), nullptr);
    gpu->hasColors = true;
  } else {
    glVertexAttrib4f(2, 1, 1, 1, 1);
  }
  std::vector<std::uint32_t> all;
  all.reserve(mesh->triangles.size() + mesh->edges.size() + mesh->lines.size() + mesh->points.size());
  all.insert(all.end(), mesh->triangles.begin(), mesh->triangles.end());
  gpu->edgeOffset = all.size();
  all.insert(all.end(), mesh->edges.begin(), mesh->edges.end());
  gpu->lineOffset = all.size();
  all.insert(all.end(), mesh->lines.begin(), mesh->lines.end());
  gpu->pointOffset = all.size();
  all.insert(all.end(), mesh->points.begin(), mesh->points.end());
  uploadArray(gpu->indices, GL_ELEMENT_ARRAY_BUFFER, all);
  glBindVertexArray(0);
  log::debug(kLogRender, "uploaded mesh {} ({} vertices, {} triangles)", mesh->id(), mesh->positions.size(),
             mesh->triangleCount());
  return *meshes_.emplace(mesh->id(), std::move(gpu)).first->second;
}

void Renderer::sweepMeshCache() {
  // Erasing frees GPU buffers of meshes no longer in any Show; iteration allocates nothing.
  std::erase_if(meshes_, [](const auto& entry) { return entry.second->source.expired(); });
}

void Renderer::setLights(const Show& show) {
  std::array<float, 4 * runtime::kMaxLights> color{}, position{}, direction{};
  std::array<float, 2 * runtime::kMaxLights> spot{};
  int n = 0;
  for (const runtime::Light& l : show.lights()) {
    if (!l.on) continue;
    const auto i = static_cast<std::size_t>(n);
    const Vec3 d = normalize(l.direction);
    color[i * 4 + 0] = l.color.r;
    color[i * 4 + 1] = l.color.g;
    color[i * 4 + 2] = l.color.b;
    color[i * 4 + 3] = static_cast<float>(l.type);
    position[i * 4 + 0] = l.position.x;
    position[i * 4 + 1] = l.position.y;
    position[i * 4 + 2] = l.position.z;
    position[i * 4 + 3] = l.attenuation1;
    direction[i * 4 + 0] = d.x;
    direction[i * 4 + 1] = d.y;
    direction[i * 4 + 2] = d.z;
    direction[i * 4 + 3] = l.attenuation2;
    spot[i * 2 + 0] = std::cos(l.angle);
    spot[i * 2 + 1] = l.exponent;
    ++n;
  }
  const LitUniforms& u = *litUniforms_;
  glUniform1i(u.lightCount, n);
  if (n == 0) return;
  glUniform4fv(u.lightColor, n, color.data());
  glUniform4fv(u.lightPosition, n, position.data());
  glUniform4fv(u.lightDirection, n, direction.data());
  glUniform2fv(u.lightSpot, n, spot.data());
}

void Renderer::draw(const Show& show, const runtime::ViewTransforms& view, Size viewport) {
  counts_ = {};
  const runtime::Color3 bg = show.global().background;
  glViewport(0, 0, static_cast<GLsizei>(viewport.width), static_cast<GLsizei>(viewport.height));
  glClearColor(bg.r, bg.g, bg.b, 1.0f);
  glClearDepthf(1.0f);
  glDepthMask(GL_TRUE);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);

  const Mat4 viewProjection = view.projection * view.view;
  glUseProgram(lit_.id());
  glUniformMatrix4fv(litUniforms_->viewProjection, 1, GL_FALSE, viewProjection.data());
  glUniform3f(litUniforms_->eye, view.eye.x, view.eye.y, view.eye.z);
  setLights(show);
  glUseProgram(color_.id());
  glUniformMatrix4fv(colorUniforms_->viewProjection, 1, GL_FALSE, viewProjection.data());

  const auto& nodes = show.nodes();
  for (runtime::NodeId i = 0; i < nodes.size(); ++i) {
    const runtime::SceneNode& node = nodes[i];
    if (!node.visible || !node.mesh) continue;
    drawNode(show, node, view.model * show.worldTransform(i), view);
  }
  glBindVertexArray(0);
  if (++framesSinceSweep_ >= 600) {
    framesSinceSweep_ = 0;
    sweepMeshCache();
  }
}

void Renderer::drawNode(const Show& show, const runtime::SceneNode& node, const Mat4& model,
                        const runtime::ViewTransforms& view) {
  (void)view;
  GpuMesh& gpu = upload(node.mesh);
  glBindVertexArray(gpu.vao.id());
  const std::array<float, 9> normals = normalMatrix(model);
  const runtime::Mesh& mesh = *node.mesh;

  for (std::size_t p = 0; p < mesh.parts.size(); ++p) {
    const runtime::MeshPart& mp = mesh.parts[p];
    const runtime::PartId partId = node.partIds[p];
    if (!show.part(partId).selected) continue;
    const PartStyle& style = show.resolvedStyle(partId);
    ++counts_.parts;

    if (style.render.hiddenSurfaceRemoval) {
      glEnable(GL_DEPTH_TEST);
      glDepthFunc(GL_LESS);
    } else {
      glDisable(GL_DEPTH_TEST);
    }
    switch (style.render.faceCulling) {
      case FaceCulling::kOff: glDisable(GL_CULL_FACE); break;
      case FaceCulling::kBack:
        glEnable(GL_CULL_FACE);
        glCullFace(GL_BACK);
        break;
      case FaceCulling::kFront:
        glEnable(GL_CULL_FACE);
        glCullFace(GL_FRONT);
        break;
    }

    if (style.render.primType == PrimType::kSolid && mp.triangleIndexCount > 0) {
      const LitUniforms& u = *litUniforms_;
      glUseProgram(lit_.id());
      glUniformMatrix4fv(u.model, 1, GL_FALSE, model.data());
      glUniformMatrix3fv(u.normalMatrix, 1, GL_FALSE, normals.data());
      const runtime::SurfaceAttributes& front = style.front;
      const runtime::SurfaceAttributes& back = style.render.faceDistinguishing ? style.back : style.front;
      setSurface(u.front, front);
      setSurface(u.back, back);
      const bool lit = front.illumination != Illumination::kNone && front.illumination != Illumination::kInterpColor;
      glUniform1i(u.lit, lit ? 1 : 0);
      glUniform1i(u.useVertexColor, front.illumination == Illumination::kInterpColor && gpu.hasColors ? 1 : 0);
      glUniform1i(u.flat, front.illumination == Illumination::kPerFacet ? 1 : 0);
      glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(mp.triangleIndexCount), GL_UNSIGNED_INT,
                     reinterpret_cast<const void*>(std::size_t{mp.firstTriangleIndex} * sizeof(std::uint32_t)));
      ++counts_.drawCalls;
      counts_.triangles += mp.triangleIndexCount / 3;
      counts_.facets += mp.facetCount;
    }

    const bool wire = style.render.primType == PrimType::kWireframe;
    const bool markers = style.render.primType == PrimType::kMarkers;
    if (wire || mp.lineIndexCount > 0 || markers || mp.pointIndexCount > 0) {
      const ColorUniforms& u = *colorUniforms_;
      glUseProgram(color_.id());
      glUniformMatrix4fv(u.model, 1, GL_FALSE, model.data());
      const runtime::Color3 lc = style.lines.color;
      glUniform4f(u.color, lc.r, lc.g, lc.b, 1.0f);
      glLineWidth(style.lines.width);
      auto drawRange = [&](GLenum mode, std::size_t offset, std::uint32_t first, std::uint32_t count) {
        if (count == 0) return;
        glDrawElements(mode, static_cast<GLsizei>(count), GL_UNSIGNED_INT,
                       reinterpret_cast<const void*>((offset + first) * sizeof(std::uint32_t)));
        ++counts_.drawCalls;
      };
      if (wire) {
        drawRange(GL_LINES, gpu.edgeOffset, mp.firstEdgeIndex, mp.edgeIndexCount);
        counts_.lines += mp.edgeIndexCount / 2;
      }
      drawRange(GL_LINES, gpu.lineOffset, mp.firstLineIndex, mp.lineIndexCount);
      counts_.lines += mp.lineIndexCount / 2;
      const runtime::Color3 mc = style.markers.color;
      glUniform4f(u.color, mc.r, mc.g, mc.b, 1.0f);
      const bool dot = style.markers.type == runtime::MarkerType::kDot;
      glUniform1f(u.pointSize, dot ? 1.0f : style.markers.scaleFactor);
      if (markers) {
        // Markers at the part's vertices: every index of its triangles, edges and lines.
        drawRange(GL_POINTS, 0, mp.firstTriangleIndex, mp.triangleIndexCount);
        drawRange(GL_POINTS, gpu.edgeOffset, mp.firstEdgeIndex, mp.edgeIndexCount);
        counts_.points += mp.triangleIndexCount + mp.edgeIndexCount;
      }
      drawRange(GL_POINTS, gpu.pointOffset, mp.firstPointIndex, mp.pointIndexCount);
      counts_.points += mp.pointIndexCount;
    }
  }
}

}  // namespace basalt::render
