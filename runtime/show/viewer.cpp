#include "runtime/show/viewer.h"

#include <cmath>

namespace basalt::runtime {

Mat4 cameraTransform(const Vec3& position, const Vec3& rotationDegrees) {
  return Mat4::translation(position) * Mat4::rotationY(rotationDegrees.y) * Mat4::rotationX(rotationDegrees.x) *
         Mat4::rotationZ(rotationDegrees.z);
}

std::optional<float> HeightField::heightAt(float x, float z) const {
  if (columns < 2 || rows < 2 || spacing <= 0 || heights.size() < std::size_t{columns} * rows) return std::nullopt;
  const float u = (x - origin.x) / spacing;
  const float v = (z - origin.z) / spacing;
  const auto maxU = static_cast<float>(columns - 1);
  const auto maxV = static_cast<float>(rows - 1);
  if (!(u >= 0 && v >= 0 && u <= maxU && v <= maxV)) return std::nullopt;  // also rejects NaN
  // The cell's lower corner; the last row and column belong to the cell before them.
  const auto i = static_cast<std::uint32_t>(std::fmin(std::floor(u), maxU - 1));
  const auto j = static_cast<std::uint32_t>(std::fmin(std::floor(v), maxV - 1));
  const float fu = u - static_cast<float>(i);
  const float fv = v - static_cast<float>(j);
  const auto at = [&](std::uint32_t c, std::uint32_t r) { return heights[std::size_t{r} * columns + c]; };
  const float top = at(i, j) + (at(i + 1, j) - at(i, j)) * fu;
  const float bottom = at(i, j + 1) + (at(i + 1, j + 1) - at(i, j + 1)) * fu;
  return origin.y + top + (bottom - top) * fv;
}

}  // namespace basalt::runtime
