#include "runtime/formats/polygon.h"

#include <algorithm>
#include <cmath>

namespace basalt::formats {

Vec3 newellNormal(std::span<const Vec3> corners) {
  Vec3 n{0, 0, 0};
  const std::size_t count = corners.size();
  for (std::size_t i = 0; i < count; ++i) {
    const Vec3& a = corners[i];
    const Vec3& b = corners[(i + 1) % count];
    n.x += (a.y - b.y) * (a.z + b.z);
    n.y += (a.z - b.z) * (a.x + b.x);
    n.z += (a.x - b.x) * (a.y + b.y);
  }
  return n;
}

namespace {

struct Point2 {
  double x, y;
};

double cross2(const Point2& o, const Point2& a, const Point2& b) {
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

/// Projects the corners onto the plane of the polygon, so that they wind counter-clockwise.
std::vector<Point2> projectCounterClockwise(std::span<const Vec3> corners, const Vec3& normal) {
  // Drop the axis the normal points along most; keep the winding by choosing the other two in
  // cyclic order, flipping when that axis' component is negative.
  const float ax = std::fabs(normal.x), ay = std::fabs(normal.y), az = std::fabs(normal.z);
  std::vector<Point2> p(corners.size());
  for (std::size_t i = 0; i < corners.size(); ++i) {
    const double x = static_cast<double>(corners[i].x), y = static_cast<double>(corners[i].y),
                 z = static_cast<double>(corners[i].z);
    if (az >= ax && az >= ay) {
      p[i] = {x, normal.z >= 0 ? y : -y};
    } else if (ax >= ay) {
      p[i] = {y, normal.x >= 0 ? z : -z};
    } else {
      p[i] = {z, normal.y >= 0 ? x : -x};
    }
  }
  return p;
}

bool sameSpot(const Point2& a, const Point2& b) { return a.x == b.x && a.y == b.y; }

/// True when p lies inside or on the triangle abc (counter-clockwise).
bool insideTriangle(const Point2& p, const Point2& a, const Point2& b, const Point2& c) {
  return cross2(a, b, p) >= 0 && cross2(b, c, p) >= 0 && cross2(c, a, p) >= 0;
}

}  // namespace

bool triangulatePolygon(std::span<const Vec3> corners, std::vector<std::uint32_t>& out, std::uint64_t budget) {
  const auto n = static_cast<std::uint32_t>(corners.size());
  if (n < 3) return true;
  if (n == 3) {
    out.insert(out.end(), {0u, 1u, 2u});
    return true;
  }
  const Vec3 normal = newellNormal(corners);
  const std::vector<Point2> p = projectCounterClockwise(corners, normal);

  // Convex polygons (the usual quad) are fanned: no corner turns right.
  bool convex = true;
  for (std::uint32_t i = 0; i < n && convex; ++i) {
    if (cross2(p[(i + n - 1) % n], p[i], p[(i + 1) % n]) < 0) convex = false;
  }
  if (convex) {
    for (std::uint32_t i = 1; i + 1 < n; ++i) out.insert(out.end(), {0u, i, i + 1});
    return true;
  }

  // Ear clipping over a ring of the corners left.
  std::vector<std::uint32_t> prev(n), next(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    prev[i] = (i + n - 1) % n;
    next[i] = (i + 1) % n;
  }
  std::uint32_t left = n;
  std::uint32_t current = 0;
  std::uint32_t sinceLastEar = 0;
  std::uint64_t tests = 0;
  while (left > 3) {
    if (tests > budget) {
      // Over budget: fan what is left and say so.
      const std::uint32_t start = current;
      std::uint32_t a = next[start];
      while (next[a] != start) {
        out.insert(out.end(), {start, a, next[a]});
        a = next[a];
      }
      return false;
    }
    const std::uint32_t a = prev[current], b = current, c = next[current];
    bool ear = cross2(p[a], p[b], p[c]) > 0;
    if (ear) {
      for (std::uint32_t v = next[c]; v != a; v = next[v]) {
        ++tests;
        // Corners at the same spot as the ear's own (repeated vertices) do not block it.
        if (sameSpot(p[v], p[a]) || sameSpot(p[v], p[b]) || sameSpot(p[v], p[c])) continue;
        if (insideTriangle(p[v], p[a], p[b], p[c])) {
          ear = false;
          break;
        }
      }
    }
    // After a whole round without an ear the polygon is degenerate (collinear or crossing
    // itself): clip anyway, so that n - 2 triangles still come out.
    if (ear || sinceLastEar >= left) {
      out.insert(out.end(), {a, b, c});
      next[a] = c;
      prev[c] = a;
      --left;
      current = a;
      sinceLastEar = 0;
    } else {
      current = c;
      ++sinceLastEar;
    }
  }
  out.insert(out.end(), {prev[current], current, next[current]});
  return true;
}

PolygonShape measurePolygon(std::span<const Vec3> corners) {
  PolygonShape shape;
  const std::size_t n = corners.size();
  if (n < 3) {
    shape.degenerate = true;
    return shape;
  }
  const Vec3 newell = newellNormal(corners);
  const float twiceArea = length(newell);
  shape.area = twiceArea * 0.5f;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) shape.diameter = std::max(shape.diameter, length(corners[j] - corners[i]));
  }
  if (!(twiceArea > 1e-12f * std::max(1.0f, shape.diameter * shape.diameter))) {
    shape.degenerate = true;
    return shape;
  }
  shape.normal = newell / twiceArea;
  Vec3 centroid{0, 0, 0};
  for (const Vec3& c : corners) centroid += c;
  centroid = centroid / static_cast<float>(n);
  shape.planeOffset = dot(shape.normal, centroid);
  float longest = -1;
  for (std::size_t i = 0; i < n; ++i) {
    shape.maxPlaneDistance =
        std::max(shape.maxPlaneDistance, std::fabs(dot(shape.normal, corners[i]) - shape.planeOffset));
    const float side = length(corners[(i + 1) % n] - corners[i]);
    if (side > longest) {
      longest = side;
      shape.longestSide = static_cast<std::uint32_t>(i);
    }
  }
  // Convex: at every corner the outline turns the same way as the normal says, allowing
  // straight corners (collinear points along a side).
  const float tolerance = 1e-6f * std::max(1.0f, shape.diameter * shape.diameter);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& a = corners[(i + n - 1) % n];
    const Vec3& b = corners[i];
    const Vec3& c = corners[(i + 1) % n];
    if (dot(cross(b - a, c - b), shape.normal) < -tolerance) {
      shape.reflexCorner = static_cast<std::int32_t>(i);
      break;
    }
  }
  return shape;
}

}  // namespace basalt::formats
