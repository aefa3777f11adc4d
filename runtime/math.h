#pragma once

/// \file
/// \brief Small vector and matrix types for the Show and the renderer. Matrices are column-major
/// (as OpenGL expects): `m[c * 4 + r]` is row r of column c, and vectors are columns (M * v).

#include <array>
#include <cmath>
#include <numbers>

namespace basalt {

struct Vec2 {
  float x = 0, y = 0;
  friend bool operator==(const Vec2&, const Vec2&) = default;
};

struct Vec3 {
  float x = 0, y = 0, z = 0;
  friend bool operator==(const Vec3&, const Vec3&) = default;
  constexpr Vec3 operator+(const Vec3& o) const { return {x + o.x, y + o.y, z + o.z}; }
  constexpr Vec3 operator-(const Vec3& o) const { return {x - o.x, y - o.y, z - o.z}; }
  constexpr Vec3 operator-() const { return {-x, -y, -z}; }
  constexpr Vec3 operator*(float s) const { return {x * s, y * s, z * s}; }
  constexpr Vec3 operator/(float s) const { return {x / s, y / s, z / s}; }
  constexpr Vec3& operator+=(const Vec3& o) { return *this = *this + o; }
  constexpr Vec3& operator-=(const Vec3& o) { return *this = *this - o; }
};

struct Vec4 {
  float x = 0, y = 0, z = 0, w = 0;
  friend bool operator==(const Vec4&, const Vec4&) = default;
  [[nodiscard]] constexpr Vec3 xyz() const { return {x, y, z}; }
};

constexpr float dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
constexpr Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float length(const Vec3& v) { return std::sqrt(dot(v, v)); }
/// \brief The unit vector along `v`, or `v` itself when it has no length.
inline Vec3 normalize(const Vec3& v) {
  const float l = length(v);
  return l > 0 ? v / l : v;
}
constexpr Vec3 componentMul(const Vec3& a, const Vec3& b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
constexpr float radians(float degrees) { return degrees * std::numbers::pi_v<float> / 180.0f; }

/// \brief A 4x4 column-major matrix.
struct Mat4 {
  std::array<float, 16> m{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

  static constexpr Mat4 identity() { return Mat4{}; }
  static Mat4 fromColumnMajor(const float* values);
  static Mat4 translation(const Vec3& t);
  static Mat4 scaling(const Vec3& s);
  /// \brief Rotation by `degrees` about the X, Y or Z axis (right-handed, counter-clockwise
  /// looking down the axis towards the origin).
  static Mat4 rotationX(float degrees);
  static Mat4 rotationY(float degrees);
  static Mat4 rotationZ(float degrees);
  /// \brief Rotation by `degrees` about an arbitrary unit axis.
  static Mat4 rotation(float degrees, const Vec3& axis);
  /// \brief OpenGL-style perspective projection; `fovY` in degrees.
  static Mat4 perspective(float fovYDegrees, float aspect, float zNear, float zFar);
  /// \brief An asymmetric frustum (glFrustum).
  static Mat4 frustum(float left, float right, float bottom, float top, float zNear, float zFar);
  static Mat4 orthographic(float left, float right, float bottom, float top, float zNear, float zFar);
  static Mat4 lookAt(const Vec3& eye, const Vec3& center, const Vec3& up);

  [[nodiscard]] constexpr float operator()(int row, int col) const {
    return m[static_cast<std::size_t>(col) * 4 + static_cast<std::size_t>(row)];
  }
  constexpr float& operator()(int row, int col) {
    return m[static_cast<std::size_t>(col) * 4 + static_cast<std::size_t>(row)];
  }
  [[nodiscard]] const float* data() const { return m.data(); }

  [[nodiscard]] Mat4 operator*(const Mat4& o) const;
  [[nodiscard]] Vec4 operator*(const Vec4& v) const;
  /// \brief Transforms a point (w = 1) and divides by w.
  [[nodiscard]] Vec3 transformPoint(const Vec3& p) const;
  /// \brief Transforms a direction (w = 0).
  [[nodiscard]] Vec3 transformDirection(const Vec3& d) const;
  [[nodiscard]] Mat4 transposed() const;
  /// \brief The inverse; the identity if the matrix is singular.
  [[nodiscard]] Mat4 inverted() const;

  friend bool operator==(const Mat4&, const Mat4&) = default;
};

}  // namespace basalt
