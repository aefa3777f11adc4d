#include "support/render_fixture.h"

#include <cmath>

#include "support/golden.h"
#include "support/test_paths.h"

namespace basalt::test {

namespace {

std::unique_ptr<RenderContext>& contextSlot() {
  static std::unique_ptr<RenderContext> context;
  return context;
}

/// Releases the GL objects, the context and the EGL display when the tests are done, before
/// main() returns: the driver's threads are gone by the time LeakSanitizer stops the world.
class ReleaseRenderContext final : public ::testing::Environment {
 public:
  void TearDown() override {
    if (auto& c = contextSlot()) {
      c->renderer.reset();
      c->output.reset();
      c.reset();
    }
  }
};

[[maybe_unused]] ::testing::Environment* const kReleaseRenderContext =
    ::testing::AddGlobalTestEnvironment(new ReleaseRenderContext);

}  // namespace

RenderContext& renderContext() {
  auto& slot = contextSlot();
  if (slot) return *slot;
  slot = std::make_unique<RenderContext>();
  RenderContext& c = *slot;
  auto output = render::createHeadlessOutput({kRenderSize, kRenderSize});
  if (!output) {
    c.unavailable = output.error().describe();
    return c;
  }
  c.output = std::move(*output);
  auto renderer = render::Renderer::create();
  if (!renderer) {
    c.unavailable = "the renderer does not start: " + renderer.error().describe();
    c.output.reset();
    return c;
  }
  c.renderer = std::move(*renderer);
  return c;
}

void RenderTest::SetUp() {
  RenderContext& c = renderContext();
  if (!c.renderer) {
    if (c.unavailable.find("renderer does not start") != std::string::npos) FAIL() << c.unavailable;
    GTEST_SKIP() << "no headless EGL here: " << c.unavailable;
  }
}

Image RenderTest::render(const runtime::Show& show, const runtime::ViewTransforms& view) {
  EXPECT_TRUE(output().beginFrame());
  renderer().draw(show, view, output().size());
  Image image;
  auto r = output().readBack(image);
  EXPECT_TRUE(r) << (r ? "" : r.error().describe());
  return image;
}

Image RenderTest::renderShow(const runtime::Show& show) {
  EXPECT_TRUE(output().beginFrame());
  renderer().drawShow(show, {0, 0, kRenderSize, kRenderSize});
  Image image;
  auto r = output().readBack(image);
  EXPECT_TRUE(r) << (r ? "" : r.error().describe());
  return image;
}

runtime::ViewTransforms testCamera(float distance, float halfWidth, float zNear, float zFar) {
  runtime::ViewTransforms t;
  t.eye = {0, 0, distance};
  t.view = Mat4::translation({0, 0, -distance});
  const float k = zNear / distance;
  t.projection = Mat4::frustum(-halfWidth * k, halfWidth * k, -halfWidth * k, halfWidth * k, zNear, zFar);
  return t;
}

namespace {

void pixelRay(const runtime::ViewTransforms& view, std::uint32_t x, std::uint32_t y, Vec3& origin, Vec3& dir) {
  const float size = static_cast<float>(kRenderSize);
  const float nx = 2.0f * (static_cast<float>(x) + 0.5f) / size - 1.0f;
  const float ny = 2.0f * (static_cast<float>(kRenderSize - 1 - y) + 0.5f) / size - 1.0f;
  const Mat4 inverse = (view.projection * view.view).inverted();
  const Vec3 nearPoint = inverse.transformPoint({nx, ny, -1});
  const Vec3 farPoint = inverse.transformPoint({nx, ny, 1});
  origin = nearPoint;
  dir = normalize(farPoint - nearPoint);
}

}  // namespace

Vec3 pixelOnPlane(const runtime::ViewTransforms& view, std::uint32_t x, std::uint32_t y, float planeZ) {
  Vec3 o, d;
  pixelRay(view, x, y, o, d);
  const float t = (planeZ - o.z) / d.z;
  return o + d * t;
}

bool pixelOnSphere(const runtime::ViewTransforms& view, std::uint32_t x, std::uint32_t y, const Vec3& centre,
                   float radius, Vec3& hit) {
  Vec3 o, d;
  pixelRay(view, x, y, o, d);
  const Vec3 oc = o - centre;
  const float b = dot(oc, d);
  const float c = dot(oc, oc) - radius * radius;
  const float disc = b * b - c;
  if (disc < 0) return false;
  hit = o + d * (-b - std::sqrt(disc));
  return true;
}

Vec2 worldToPixel(const runtime::ViewTransforms& view, const Vec3& world) {
  const Vec3 ndc = (view.projection * view.view).transformPoint(world);
  const float size = static_cast<float>(kRenderSize);
  return {(ndc.x + 1) * 0.5f * size - 0.5f, size - 1 - ((ndc.y + 1) * 0.5f * size - 0.5f)};
}

std::shared_ptr<runtime::Mesh> makeQuad(float half, float z, int n, const std::string& partName) {
  auto mesh = std::make_shared<runtime::Mesh>();
  const auto side = static_cast<std::uint32_t>(n + 1);
  for (std::uint32_t j = 0; j < side; ++j) {
    for (std::uint32_t i = 0; i < side; ++i) {
      const float u = static_cast<float>(i) / static_cast<float>(n);
      const float v = static_cast<float>(j) / static_cast<float>(n);
      mesh->positions.push_back({-half + 2 * half * u, -half + 2 * half * v, z});
      mesh->normals.push_back({0, 0, 1});
      mesh->texcoords.push_back({u, v});
    }
  }
  runtime::MeshPart part;
  part.name = partName;
  for (std::uint32_t j = 0; j + 1 < side; ++j) {
    for (std::uint32_t i = 0; i + 1 < side; ++i) {
      const std::uint32_t a = j * side + i, b = a + 1, c = a + side + 1, d = a + side;
      for (std::uint32_t v : {a, b, c, a, c, d}) mesh->triangles.push_back(v);
      for (std::uint32_t v : {a, b, b, c, c, d, d, a}) mesh->edges.push_back(v);
    }
  }
  part.triangleIndexCount = static_cast<std::uint32_t>(mesh->triangles.size());
  part.edgeIndexCount = static_cast<std::uint32_t>(mesh->edges.size());
  part.facetCount = static_cast<std::uint32_t>(n * n);
  mesh->parts.push_back(part);
  return mesh;
}

std::shared_ptr<runtime::Mesh> makeSphere(float radius, int rings, int segments, const std::string& partName) {
  auto mesh = std::make_shared<runtime::Mesh>();
  for (int r = 0; r <= rings; ++r) {
    const float theta = std::numbers::pi_v<float> * static_cast<float>(r) / static_cast<float>(rings);
    for (int s = 0; s <= segments; ++s) {
      const float phi = 2 * std::numbers::pi_v<float> * static_cast<float>(s) / static_cast<float>(segments);
      const Vec3 n{std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi)};
      mesh->positions.push_back(n * radius);
      mesh->normals.push_back(n);
      mesh->texcoords.push_back({static_cast<float>(s) / static_cast<float>(segments),
                                 1 - static_cast<float>(r) / static_cast<float>(rings)});
    }
  }
  const auto stride = static_cast<std::uint32_t>(segments + 1);
  for (std::uint32_t r = 0; r < static_cast<std::uint32_t>(rings); ++r) {
    for (std::uint32_t s = 0; s < static_cast<std::uint32_t>(segments); ++s) {
      const std::uint32_t a = r * stride + s, b = a + stride, c = b + 1, d = a + 1;
      for (std::uint32_t v : {a, b, c, a, c, d}) mesh->triangles.push_back(v);
      // Each quad's outline: the grid of meridians and parallels.
      for (std::uint32_t v : {a, b, b, c, c, d, d, a}) mesh->edges.push_back(v);
    }
  }
  runtime::MeshPart part;
  part.name = partName;
  part.edgeIndexCount = static_cast<std::uint32_t>(mesh->edges.size());
  part.triangleIndexCount = static_cast<std::uint32_t>(mesh->triangles.size());
  part.facetCount = part.triangleIndexCount / 3;
  mesh->parts.push_back(part);
  return mesh;
}

std::shared_ptr<runtime::Mesh> combine(const std::vector<std::shared_ptr<runtime::Mesh>>& meshes) {
  auto out = std::make_shared<runtime::Mesh>();
  for (const auto& m : meshes) {
    const auto base = static_cast<std::uint32_t>(out->positions.size());
    const auto tri = static_cast<std::uint32_t>(out->triangles.size());
    const auto edge = static_cast<std::uint32_t>(out->edges.size());
    const auto line = static_cast<std::uint32_t>(out->lines.size());
    const auto point = static_cast<std::uint32_t>(out->points.size());
    const std::size_t n = m->positions.size();
    out->positions.insert(out->positions.end(), m->positions.begin(), m->positions.end());
    auto fill = [n](auto& into, const auto& from, auto fallback) {
      if (from.size() == n) {
        into.insert(into.end(), from.begin(), from.end());
      } else {
        into.insert(into.end(), n, fallback);
      }
    };
    fill(out->normals, m->normals, Vec3{0, 0, 1});
    fill(out->texcoords, m->texcoords, Vec2{0, 0});
    if (!m->colors.empty() || !out->colors.empty()) {
      out->colors.resize(base, Vec4{1, 1, 1, 1});
      fill(out->colors, m->colors, Vec4{1, 1, 1, 1});
    }
    for (std::uint32_t v : m->triangles) out->triangles.push_back(base + v);
    for (std::uint32_t v : m->edges) out->edges.push_back(base + v);
    for (std::uint32_t v : m->lines) out->lines.push_back(base + v);
    for (std::uint32_t v : m->points) out->points.push_back(base + v);
    for (runtime::MeshPart p : m->parts) {
      p.firstTriangleIndex += tri;
      p.firstEdgeIndex += edge;
      p.firstLineIndex += line;
      p.firstPointIndex += point;
      out->parts.push_back(p);
    }
  }
  return out;
}

std::shared_ptr<runtime::Mesh> makePolyline(const std::vector<Vec3>& points, const std::string& partName) {
  auto mesh = std::make_shared<runtime::Mesh>();
  mesh->positions = points;
  mesh->normals.assign(points.size(), Vec3{0, 0, 1});
  for (std::uint32_t i = 0; i + 1 < points.size(); ++i) {
    mesh->lines.push_back(i);
    mesh->lines.push_back(i + 1);
  }
  runtime::MeshPart part;
  part.name = partName;
  part.lineIndexCount = static_cast<std::uint32_t>(mesh->lines.size());
  mesh->parts.push_back(part);
  return mesh;
}

std::shared_ptr<runtime::Mesh> makePoints(const std::vector<Vec3>& points, const std::string& partName) {
  auto mesh = std::make_shared<runtime::Mesh>();
  mesh->positions = points;
  mesh->normals.assign(points.size(), Vec3{0, 0, 1});
  for (std::uint32_t i = 0; i < points.size(); ++i) mesh->points.push_back(i);
  runtime::MeshPart part;
  part.name = partName;
  part.pointIndexCount = static_cast<std::uint32_t>(points.size());
  mesh->parts.push_back(part);
  return mesh;
}

runtime::Show showOf(std::shared_ptr<const runtime::Mesh> mesh) {
  runtime::Show show;
  runtime::SceneNode node;
  node.name = "object";
  node.mesh = std::move(mesh);
  show.addNode(std::move(node));
  show.view().objectScale = runtime::ObjectScale::kOriginal;
  return show;
}

void lightsOff(runtime::Show& show) {
  for (runtime::Light& l : show.lights()) l.on = false;
}

std::string matchesGolden(const Image& image, const std::string& name) {
  return compareWithGolden(image, sourceDir() / "tests/render/golden" / (name + ".png"));
}

}  // namespace basalt::test
