#include "support/polyhedra.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "runtime/math.h"

namespace basalt::test {
namespace {

// A half-space dot(outward, x) <= offset; `screen` says whether its facet is written.
struct Wall {
  Vec3 outward;
  float offset = 1;
  bool screen = true;
};

using Polygon = std::vector<Vec3>;

Polygon clip(const Polygon& in, const Wall& w) {
  Polygon out;
  for (std::size_t i = 0; i < in.size(); ++i) {
    const Vec3& a = in[i];
    const Vec3& b = in[(i + 1) % in.size()];
    const float da = dot(w.outward, a) - w.offset, db = dot(w.outward, b) - w.offset;
    if (da <= 0) out.push_back(a);
    if ((da < 0 && db > 0) || (da > 0 && db < 0)) out.push_back(a + (b - a) * (da / (da - db)));
  }
  return out;
}

std::string toObj(const std::vector<Wall>& walls) {
  std::vector<Vec3> vertices;
  std::string faces;
  auto indexOf = [&vertices](const Vec3& p) {
    for (std::size_t i = 0; i < vertices.size(); ++i) {
      if (length(vertices[i] - p) < 1e-5f) return i + 1;
    }
    vertices.push_back(p);
    return vertices.size();
  };
  for (std::size_t i = 0; i < walls.size(); ++i) {
    if (!walls[i].screen) continue;
    const Vec3 n = normalize(walls[i].outward);
    const Vec3 helper = std::fabs(n.y) < 0.9f ? Vec3{0, 1, 0} : Vec3{1, 0, 0};
    const Vec3 u = normalize(cross(helper, n));
    const Vec3 v = cross(n, u);
    const Vec3 c = n * (walls[i].offset / length(walls[i].outward));
    const float big = 100;
    // Counter-clockwise about the inward normal -n: walk u, then -v.
    Polygon poly{c - u * big + v * big, c + u * big + v * big, c + u * big - v * big, c - u * big - v * big};
    if (dot(cross(poly[1] - poly[0], poly[2] - poly[1]), -n) < 0) poly = {poly[3], poly[2], poly[1], poly[0]};
    for (std::size_t j = 0; j < walls.size(); ++j) {
      if (j != i) poly = clip(poly, walls[j]);
    }
    std::string face = "f";
    std::size_t last = 0;
    std::size_t first = 0;
    for (const Vec3& p : poly) {
      const std::size_t k = indexOf(p);
      if (k == last) continue;  // a corner where more than three walls meet comes out twice
      if (first == 0) first = k;
      face += fmt::format(" {}", k);
      last = k;
    }
    if (last == first) face.resize(face.rfind(' '));
    faces += face + "\n";
  }
  std::string obj;
  for (const Vec3& p : vertices) obj += fmt::format("v {:.7g} {:.7g} {:.7g}\n", p.x, p.y, p.z);
  return obj + faces;
}

}  // namespace

std::string cubeDisplayObj() {
  return toObj({{{1, 0, 0}}, {{-1, 0, 0}}, {{0, 1, 0}}, {{0, -1, 0}}, {{0, 0, 1}}, {{0, 0, -1}}});
}

std::string prismDisplayObj() {
  std::vector<Wall> walls;
  for (int i = 0; i < 10; ++i) {
    const float a = 2.0f * std::numbers::pi_v<float> * static_cast<float>(i) / 10.0f;
    walls.push_back({{std::cos(a), 0, std::sin(a)}});
  }
  walls.push_back({{0, 1, 0}, 1, false});
  walls.push_back({{0, -1, 0}, 1, false});
  return toObj(walls);
}

std::string icositetrahedronDisplayObj() {
  // The rhombicuboctahedron's vertices are the permutations of (±1, ±1, ±(1 + √2)); the dual's
  // facets are their polar planes dot(v, x) = |v|^2 (scaled so that the inscribed sphere has
  // radius 1).
  const float big = 1.0f + std::numbers::sqrt2_v<float>;
  std::vector<Wall> walls;
  for (int axis = 0; axis < 3; ++axis) {
    for (int s = 0; s < 8; ++s) {
      const float a = (s & 1) ? -1.0f : 1.0f, b = (s & 2) ? -1.0f : 1.0f, c = (s & 4) ? -big : big;
      Vec3 v = axis == 0 ? Vec3{c, a, b} : axis == 1 ? Vec3{a, c, b} : Vec3{a, b, c};
      walls.push_back({normalize(v), 1});
    }
  }
  return toObj(walls);
}

std::string reverseFacetWinding(const std::string& obj) {
  std::istringstream in(obj);
  std::string out, line;
  while (std::getline(in, line)) {
    if (line.rfind("f ", 0) == 0) {
      std::istringstream words(line.substr(2));
      std::vector<std::string> corners;
      for (std::string w; words >> w;) corners.push_back(w);
      std::reverse(corners.begin(), corners.end());
      line = "f";
      for (const std::string& c : corners) line += " " + c;
    }
    out += line + "\n";
  }
  return out;
}

}  // namespace basalt::test
