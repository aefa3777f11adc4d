#include "runtime/math.h"

#include <algorithm>

namespace basalt {

Mat4 Mat4::fromColumnMajor(const float* values) {
  Mat4 r;
  std::copy(values, values + 16, r.m.begin());
  return r;
}

Mat4 Mat4::translation(const Vec3& t) {
  Mat4 r;
  r(0, 3) = t.x;
  r(1, 3) = t.y;
  r(2, 3) = t.z;
  return r;
}

Mat4 Mat4::scaling(const Vec3& s) {
  Mat4 r;
  r(0, 0) = s.x;
  r(1, 1) = s.y;
  r(2, 2) = s.z;
  return r;
}

Mat4 Mat4::rotationX(float degrees) {
  const float c = std::cos(radians(degrees)), s = std::sin(radians(degrees));
  Mat4 r;
  r(1, 1) = c;
  r(1, 2) = -s;
  r(2, 1) = s;
  r(2, 2) = c;
  return r;
}

Mat4 Mat4::rotationY(float degrees) {
  const float c = std::cos(radians(degrees)), s = std::sin(radians(degrees));
  Mat4 r;
  r(0, 0) = c;
  r(0, 2) = s;
  r(2, 0) = -s;
  r(2, 2) = c;
  return r;
}

Mat4 Mat4::rotationZ(float degrees) {
  const float c = std::cos(radians(degrees)), s = std::sin(radians(degrees));
  Mat4 r;
  r(0, 0) = c;
  r(0, 1) = -s;
  r(1, 0) = s;
  r(1, 1) = c;
  return r;
}

Mat4 Mat4::rotation(float degrees, const Vec3& axisIn) {
  const Vec3 a = normalize(axisIn);
  const float c = std::cos(radians(degrees)), s = std::sin(radians(degrees)), t = 1 - c;
  Mat4 r;
  r(0, 0) = t * a.x * a.x + c;
  r(0, 1) = t * a.x * a.y - s * a.z;
  r(0, 2) = t * a.x * a.z + s * a.y;
  r(1, 0) = t * a.x * a.y + s * a.z;
  r(1, 1) = t * a.y * a.y + c;
  r(1, 2) = t * a.y * a.z - s * a.x;
  r(2, 0) = t * a.x * a.z - s * a.y;
  r(2, 1) = t * a.y * a.z + s * a.x;
  r(2, 2) = t * a.z * a.z + c;
  return r;
}

Mat4 Mat4::perspective(float fovYDegrees, float aspect, float zNear, float zFar) {
  const float top = zNear * std::tan(radians(fovYDegrees) / 2);
  return frustum(-top * aspect, top * aspect, -top, top, zNear, zFar);
}

Mat4 Mat4::frustum(float l, float r, float b, float t, float n, float f) {
  Mat4 p;
  p.m.fill(0);
  p(0, 0) = 2 * n / (r - l);
  p(0, 2) = (r + l) / (r - l);
  p(1, 1) = 2 * n / (t - b);
  p(1, 2) = (t + b) / (t - b);
  p(2, 2) = -(f + n) / (f - n);
  p(2, 3) = -2 * f * n / (f - n);
  p(3, 2) = -1;
  return p;
}

Mat4 Mat4::orthographic(float l, float r, float b, float t, float n, float f) {
  Mat4 p;
  p(0, 0) = 2 / (r - l);
  p(1, 1) = 2 / (t - b);
  p(2, 2) = -2 / (f - n);
  p(0, 3) = -(r + l) / (r - l);
  p(1, 3) = -(t + b) / (t - b);
  p(2, 3) = -(f + n) / (f - n);
  return p;
}

Mat4 Mat4::lookAt(const Vec3& eye, const Vec3& center, const Vec3& up) {
  const Vec3 f = normalize(center - eye);
  const Vec3 s = normalize(cross(f, up));
  const Vec3 u = cross(s, f);
  Mat4 v;
  v(0, 0) = s.x;
  v(0, 1) = s.y;
  v(0, 2) = s.z;
  v(1, 0) = u.x;
  v(1, 1) = u.y;
  v(1, 2) = u.z;
  v(2, 0) = -f.x;
  v(2, 1) = -f.y;
  v(2, 2) = -f.z;
  v(0, 3) = -dot(s, eye);
  v(1, 3) = -dot(u, eye);
  v(2, 3) = dot(f, eye);
  return v;
}

Mat4 Mat4::operator*(const Mat4& o) const {
  Mat4 r;
  for (int c = 0; c < 4; ++c) {
    for (int row = 0; row < 4; ++row) {
      float sum = 0;
      for (int k = 0; k < 4; ++k) sum += (*this)(row, k) * o(k, c);
      r(row, c) = sum;
    }
  }
  return r;
}

Vec4 Mat4::operator*(const Vec4& v) const {
  const Mat4& a = *this;
  return {a(0, 0) * v.x + a(0, 1) * v.y + a(0, 2) * v.z + a(0, 3) * v.w,
          a(1, 0) * v.x + a(1, 1) * v.y + a(1, 2) * v.z + a(1, 3) * v.w,
          a(2, 0) * v.x + a(2, 1) * v.y + a(2, 2) * v.z + a(2, 3) * v.w,
          a(3, 0) * v.x + a(3, 1) * v.y + a(3, 2) * v.z + a(3, 3) * v.w};
}

Vec3 Mat4::transformPoint(const Vec3& p) const {
  const Vec4 r = *this * Vec4{p.x, p.y, p.z, 1};
  return r.w != 0 && r.w != 1 ? Vec3{r.x / r.w, r.y / r.w, r.z / r.w} : r.xyz();
}

Vec3 Mat4::transformDirection(const Vec3& d) const { return (*this * Vec4{d.x, d.y, d.z, 0}).xyz(); }

Mat4 Mat4::transposed() const {
  Mat4 r;
  for (int c = 0; c < 4; ++c)
    for (int row = 0; row < 4; ++row) r(row, c) = (*this)(c, row);
  return r;
}

Mat4 Mat4::inverted() const {
  // Inverse as adjugate over determinant, in double precision. a[i] is column-major like m.
  double a[16];
  for (std::size_t i = 0; i < 16; ++i) a[i] = static_cast<double>(m[i]);
  double inv[16];
  inv[0] = a[5] * a[10] * a[15] - a[5] * a[11] * a[14] - a[9] * a[6] * a[15] + a[9] * a[7] * a[14] +
           a[13] * a[6] * a[11] - a[13] * a[7] * a[10];
  inv[4] = -a[4] * a[10] * a[15] + a[4] * a[11] * a[14] + a[8] * a[6] * a[15] - a[8] * a[7] * a[14] -
           a[12] * a[6] * a[11] + a[12] * a[7] * a[10];
  inv[8] = a[4] * a[9] * a[15] - a[4] * a[11] * a[13] - a[8] * a[5] * a[15] + a[8] * a[7] * a[13] +
           a[12] * a[5] * a[11] - a[12] * a[7] * a[9];
  inv[12] = -a[4] * a[9] * a[14] + a[4] * a[10] * a[13] + a[8] * a[5] * a[14] - a[8] * a[6] * a[13] -
            a[12] * a[5] * a[10] + a[12] * a[6] * a[9];
  inv[1] = -a[1] * a[10] * a[15] + a[1] * a[11] * a[14] + a[9] * a[2] * a[15] - a[9] * a[3] * a[14] -
           a[13] * a[2] * a[11] + a[13] * a[3] * a[10];
  inv[5] = a[0] * a[10] * a[15] - a[0] * a[11] * a[14] - a[8] * a[2] * a[15] + a[8] * a[3] * a[14] +
           a[12] * a[2] * a[11] - a[12] * a[3] * a[10];
  inv[9] = -a[0] * a[9] * a[15] + a[0] * a[11] * a[13] + a[8] * a[1] * a[15] - a[8] * a[3] * a[13] -
           a[12] * a[1] * a[11] + a[12] * a[3] * a[9];
  inv[13] = a[0] * a[9] * a[14] - a[0] * a[10] * a[13] - a[8] * a[1] * a[14] + a[8] * a[2] * a[13] +
            a[12] * a[1] * a[10] - a[12] * a[2] * a[9];
  inv[2] = a[1] * a[6] * a[15] - a[1] * a[7] * a[14] - a[5] * a[2] * a[15] + a[5] * a[3] * a[14] + a[13] * a[2] * a[7] -
           a[13] * a[3] * a[6];
  inv[6] = -a[0] * a[6] * a[15] + a[0] * a[7] * a[14] + a[4] * a[2] * a[15] - a[4] * a[3] * a[14] -
           a[12] * a[2] * a[7] + a[12] * a[3] * a[6];
  inv[10] = a[0] * a[5] * a[15] - a[0] * a[7] * a[13] - a[4] * a[1] * a[15] + a[4] * a[3] * a[13] +
            a[12] * a[1] * a[7] - a[12] * a[3] * a[5];
  inv[14] = -a[0] * a[5] * a[14] + a[0] * a[6] * a[13] + a[4] * a[1] * a[14] - a[4] * a[2] * a[13] -
            a[12] * a[1] * a[6] + a[12] * a[2] * a[5];
  inv[3] = -a[1] * a[6] * a[11] + a[1] * a[7] * a[10] + a[5] * a[2] * a[11] - a[5] * a[3] * a[10] - a[9] * a[2] * a[7] +
           a[9] * a[3] * a[6];
  inv[7] = a[0] * a[6] * a[11] - a[0] * a[7] * a[10] - a[4] * a[2] * a[11] + a[4] * a[3] * a[10] + a[8] * a[2] * a[7] -
           a[8] * a[3] * a[6];
  inv[11] = -a[0] * a[5] * a[11] + a[0] * a[7] * a[9] + a[4] * a[1] * a[11] - a[4] * a[3] * a[9] - a[8] * a[1] * a[7] +
            a[8] * a[3] * a[5];
  inv[15] = a[0] * a[5] * a[10] - a[0] * a[6] * a[9] - a[4] * a[1] * a[10] + a[4] * a[2] * a[9] + a[8] * a[1] * a[6] -
            a[8] * a[2] * a[5];
  const double det = a[0] * inv[0] + a[1] * inv[4] + a[2] * inv[8] + a[3] * inv[12];
  if (det == 0) return Mat4{};
  Mat4 r;
  for (std::size_t i = 0; i < 16; ++i) r.m[i] = static_cast<float>(inv[i] / det);
  return r;
}

}  // namespace basalt
