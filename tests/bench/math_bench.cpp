// Per-frame math: Basalt's runtime/math (Mat4, Vec3, Vec4) against GLM (Debian's libglm-dev,
// 0.9.9) on what the Show and the renderer compute every frame, on the same inputs in the same
// run. GLM is measured twice: with its default types (glm::mat4, plain scalar code: what a
// switch would use as is) and with its aligned SIMD types (glm::aligned_mat4 under
// GLM_FORCE_INTRINSICS: its fastest form without -march flags).
//  - multiply: `view.model * show.worldTransform(i)`, `projection * view` (Renderer::drawView);
//  - inverse: the background's inverse view-projection, the facet projection's worldFromCave;
//  - normalMatrix: the renderer's normal matrix (upper 3x3 of the inverse transpose), per node
//    and view; GLM's form is inverseTranspose(mat3(m)), as a GLM renderer would write it;
//  - transformPoint, transformDirection: scene bounds (eight corners per node), the blended
//    parts' centres, the clipping planes;
//  - viewSetup: lookAt + perspective (cave aids), frustum and orthographic (computeEyeView);
//  - rotation: a rotation about an axis (free-run motion, the script's rotations);
//  - frame: one frame's math for kNodes nodes, in the order Show and Renderer do it.
// Each benchmark runs the operation over kCount inputs per iteration. Before timing, every
// operation is checked to give the same numbers in both (a layout or convention mismatch,
// such as a transposed matrix, degrees for radians or another depth range, fails the run),
// and both inverses are compared with one computed in long double.
// Figures: ns per operation for Basalt and GLM (both forms), Basalt / GLM; the frame's math as
// a share of a 60 Hz frame. `--quick` (ctest) times each benchmark for less long.

#include <benchmark/benchmark.h>

#define GLM_FORCE_INTRINSICS
#include <glm/glm.hpp>
#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_aligned.hpp>
#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "bench_main.h"
#include "runtime/math.h"

namespace {

using basalt::Mat4;
using basalt::Vec3;

constexpr std::size_t kCount = 1024;  // inputs per benchmark iteration
constexpr std::size_t kNodes = 256;   // scene nodes in the frame benchmark

using GlmAligned = glm::aligned_mat4;

// ---- Inputs: the same values for both libraries ------------------------------------------------

/// A model matrix as scenes have them: rotation about a random axis, scale 0.1..10, translation
/// within +-100, written out by hand so that neither library makes it.
std::array<float, 16> randomModel(std::mt19937& rng) {
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f), angle(0.0f, 6.2831853f), logScale(-1.0f, 1.0f),
      offset(-100.0f, 100.0f);
  float ax = unit(rng), ay = unit(rng), az = unit(rng);
  const float len = std::sqrt(ax * ax + ay * ay + az * az) + 1e-6f;
  ax /= len;
  ay /= len;
  az /= len;
  const float a = angle(rng), c = std::cos(a), s = std::sin(a), t = 1 - c;
  const float sx = std::pow(10.0f, logScale(rng)), sy = std::pow(10.0f, logScale(rng)),
              sz = std::pow(10.0f, logScale(rng));
  // Column-major R * S with translation in the last column.
  const float r[9] = {t * ax * ax + c,      t * ax * ay + s * az, t * ax * az - s * ay,
                      t * ax * ay - s * az, t * ay * ay + c,      t * ay * az + s * ax,
                      t * ax * az + s * ay, t * ay * az - s * ax, t * az * az + c};
  return {r[0] * sx, r[1] * sx, r[2] * sx, 0, r[3] * sy,   r[4] * sy,   r[5] * sy,   0,
          r[6] * sz, r[7] * sz, r[8] * sz, 0, offset(rng), offset(rng), offset(rng), 1};
}

struct ViewInput {
  Vec3 eye, centre, up;
  float fovY, aspect, zNear, zFar;
  float left, right, bottom, top;
};

struct Inputs {
  std::vector<std::array<float, 16>> a, b;     // model matrices, column-major
  std::vector<std::array<float, 16>> general;  // projection * view * model: full 4x4s
  std::vector<Vec3> points, directions;
  std::vector<ViewInput> views;
  std::vector<Vec3> axes;
  std::vector<float> degrees;
};

Inputs makeInputs() {
  std::mt19937 rng(20240601);
  std::uniform_real_distribution<float> coord(-50.0f, 50.0f), unit(-1.0f, 1.0f), deg(-180.0f, 180.0f);
  Inputs in;
  for (std::size_t i = 0; i < kCount; ++i) {
    in.a.push_back(randomModel(rng));
    in.b.push_back(randomModel(rng));
    in.points.push_back({coord(rng), coord(rng), coord(rng)});
    in.directions.push_back({unit(rng), unit(rng), unit(rng)});
    ViewInput v;
    v.eye = {coord(rng), coord(rng), coord(rng) + 120.0f};
    v.centre = {coord(rng) * 0.1f, coord(rng) * 0.1f, coord(rng) * 0.1f};
    v.up = {unit(rng) * 0.2f, 1.0f, unit(rng) * 0.2f};
    v.fovY = 30.0f + 60.0f * (unit(rng) + 1.0f) / 2.0f;
    v.aspect = 1.0f + (unit(rng) + 1.0f) / 2.0f;
    v.zNear = 0.1f + (unit(rng) + 1.0f);
    v.zFar = 200.0f + coord(rng);
    v.left = -1.0f + 0.3f * unit(rng);
    v.right = 1.0f + 0.3f * unit(rng);
    v.bottom = -0.6f + 0.2f * unit(rng);
    v.top = 0.6f + 0.2f * unit(rng);
    in.views.push_back(v);
    in.axes.push_back({unit(rng), unit(rng), unit(rng) + 2.0f});
    in.degrees.push_back(deg(rng));
  }
  // Full 4x4s: a frustum times a model (what the background and facet code invert), made with
  // Basalt's Mat4 as the renderer makes them.
  for (std::size_t i = 0; i < kCount; ++i) {
    const ViewInput& v = in.views[i];
    const Mat4 p = Mat4::frustum(v.left, v.right, v.bottom, v.top, v.zNear, v.zFar) *
                   Mat4::translation({0, 0, -150.0f}) * Mat4::fromColumnMajor(in.a[i].data());
    in.general.push_back(p.m);
  }
  return in;
}

const Inputs& inputs() {
  static const Inputs in = makeInputs();
  return in;
}

Mat4 basaltMat(const std::array<float, 16>& m) { return Mat4::fromColumnMajor(m.data()); }
template <typename M>
M glmMat(const std::array<float, 16>& m) {
  return M(glm::make_mat4(m.data()));
}
glm::vec3 glmVec(const Vec3& v) { return {v.x, v.y, v.z}; }

/// GLM's functions take vectors of their matrix's qualifier (packed or aligned).
template <typename M>
struct QualifierOf;
template <glm::qualifier Q>
struct QualifierOf<glm::mat<4, 4, float, Q>> {
  static constexpr glm::qualifier kValue = Q;
};
template <typename M>
using Vec3Of = glm::vec<3, float, QualifierOf<M>::kValue>;
template <typename M>
using Mat3Of = glm::mat<3, 3, float, QualifierOf<M>::kValue>;
template <typename M>
Vec3Of<M> glmVec(const glm::vec3& v) {
  return Vec3Of<M>(v.x, v.y, v.z);
}
template <typename M>
Vec3Of<M> glmVec(const Vec3& v) {
  return Vec3Of<M>(v.x, v.y, v.z);
}

template <typename M>
M identity() {
  if constexpr (std::is_same_v<M, Mat4>) {
    return Mat4::identity();
  } else {
    return M(1.0f);
  }
}

template <typename M>
std::array<float, 16> raw(const M& m) {
  std::array<float, 16> r{};
  for (int c = 0; c < 4; ++c)
    for (int row = 0; row < 4; ++row) r[static_cast<std::size_t>(c * 4 + row)] = m[c][row];
  return r;
}
std::array<float, 16> raw(const Mat4& m) { return m.m; }

// ---- The operations, as each library's users write them ---------------------------------------

std::array<float, 9> basaltNormalMatrix(const Mat4& model) {  // as render/renderer.cpp does it
  const Mat4 n = model.inverted().transposed();
  return {n(0, 0), n(1, 0), n(2, 0), n(0, 1), n(1, 1), n(2, 1), n(0, 2), n(1, 2), n(2, 2)};
}
template <typename M>
std::array<float, 9> glmNormalMatrix(const M& model) {
  const Mat3Of<M> n = glm::inverseTranspose(Mat3Of<M>(model));
  return {n[0][0], n[0][1], n[0][2], n[1][0], n[1][1], n[1][2], n[2][0], n[2][1], n[2][2]};
}

/// Transforms a point and divides by w, as Mat4::transformPoint does.
template <typename M>
glm::vec3 glmPoint(const M& m, const glm::vec3& p) {
  using V4 = typename M::col_type;
  const V4 r = m * V4(p.x, p.y, p.z, 1.0f);
  return r.w != 0 && r.w != 1 ? glm::vec3(r.x, r.y, r.z) / r.w : glm::vec3(r.x, r.y, r.z);
}
template <typename M>
glm::vec3 glmDirection(const M& m, const glm::vec3& d) {
  using V4 = typename M::col_type;
  const V4 r = m * V4(d.x, d.y, d.z, 0.0f);
  return {r.x, r.y, r.z};
}

/// Mat4 has no addition (the runtime needs none); the view benchmark sums its four matrices so
/// that none can be optimised away.
Mat4 operator+(const Mat4& x, const Mat4& y) {
  Mat4 r;
  for (std::size_t i = 0; i < 16; ++i) r.m[i] = x.m[i] + y.m[i];
  return r;
}

/// The four per-view matrices folded into one, so one result stands for all four.
Mat4 basaltViewSetup(const ViewInput& v) {
  return Mat4::perspective(v.fovY, v.aspect, v.zNear, v.zFar) * Mat4::lookAt(v.eye, v.centre, v.up) +
         Mat4::frustum(v.left, v.right, v.bottom, v.top, v.zNear, v.zFar) +
         Mat4::orthographic(v.left, v.right, v.bottom, v.top, v.zNear, v.zFar);
}
template <typename M>
M glmViewSetup(const ViewInput& v) {
  return M(glm::perspective(glm::radians(v.fovY), v.aspect, v.zNear, v.zFar)) *
             M(glm::lookAt(glmVec(v.eye), glmVec(v.centre), glmVec(v.up))) +
         M(glm::frustum(v.left, v.right, v.bottom, v.top, v.zNear, v.zFar)) +
         M(glm::ortho(v.left, v.right, v.bottom, v.top, v.zNear, v.zFar));
}

Mat4 basaltRotation(float degrees, const Vec3& axis) { return Mat4::rotation(degrees, axis); }
template <typename M>
M glmRotation(float degrees, const Vec3& axis) {
  return glm::rotate(M(1.0f), glm::radians(degrees), glmVec<M>(axis));
}

// ---- One frame's math, in the order Show and Renderer do it --------------------------------------

/// A scene of kNodes nodes: node 0 is the root, every other node its child (as an OBJ's groups
/// or a .sce scene's objects are), each with a local matrix and its mesh's bounds.
template <typename M>
struct Scene {
  std::vector<M> local;
  std::vector<int> parent;
  std::vector<glm::vec3> boundsMin, boundsMax, centre;
  M global = identity<M>(), localPosition = identity<M>();
};

Scene<Mat4> basaltScene() {
  const Inputs& in = inputs();
  Scene<Mat4> s;
  for (std::size_t i = 0; i < kNodes; ++i) {
    s.local.push_back(basaltMat(in.a[i]));
    s.parent.push_back(i == 0 ? -1 : 0);
    const Vec3 p = in.points[i], d = in.directions[i];
    s.boundsMin.push_back(glmVec(p) - glm::abs(glmVec(d)));
    s.boundsMax.push_back(glmVec(p) + glm::abs(glmVec(d)));
    s.centre.push_back(glmVec(p));
  }
  return s;
}

template <typename M>
Scene<M> glmScene() {
  const Scene<Mat4> b = basaltScene();
  Scene<M> s;
  for (const Mat4& m : b.local) s.local.push_back(glmMat<M>(m.m));
  s.parent = b.parent;
  s.boundsMin = b.boundsMin;
  s.boundsMax = b.boundsMax;
  s.centre = b.centre;
  return s;
}

Vec3 toBasalt(const glm::vec3& v) { return {v.x, v.y, v.z}; }

struct FrameResult {
  std::array<float, 16> viewProjection{};
  float checksum = 0;  // the normal matrices, centres and distances summed
};

/// Show::worldTransform, computeView (scene bounds, normalisation, frustum), Renderer::drawView
/// (view-projection, per node the model, its normal matrix and the centre's distance) and
/// Show::advanceFrame's free-run rotation.
FrameResult basaltFrame(Scene<Mat4>& s) {
  const auto world = [&s](std::size_t i) {
    Mat4 m = s.local[i];
    for (int p = s.parent[i]; p >= 0; p = s.parent[static_cast<std::size_t>(p)])
      m = s.local[static_cast<std::size_t>(p)] * m;
    return m;
  };
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (std::size_t i = 0; i < kNodes; ++i) {
    const Mat4 w = world(i);
    for (int corner = 0; corner < 8; ++corner) {
      const Vec3 c{(corner & 1) ? s.boundsMax[i].x : s.boundsMin[i].x,
                   (corner & 2) ? s.boundsMax[i].y : s.boundsMin[i].y,
                   (corner & 4) ? s.boundsMax[i].z : s.boundsMin[i].z};
      const Vec3 p = w.transformPoint(c);
      lo = glm::min(lo, glmVec(p));
      hi = glm::max(hi, glmVec(p));
    }
  }
  const glm::vec3 middle = (lo + hi) * 0.5f;
  const float scale = 2.0f / glm::length(hi - lo);
  const Mat4 normalisation = Mat4::scaling({scale, scale, scale}) * Mat4::translation(-toBasalt(middle));
  const Mat4 model = s.global * s.localPosition * normalisation;
  const Mat4 view = Mat4::translation({0, 0, -3});
  const Mat4 projection = Mat4::frustum(-0.9f, 0.9f, -0.5f, 0.5f, 1.0f, 5.0f);
  FrameResult r;
  const Mat4 viewProjection = projection * view;
  r.viewProjection = viewProjection.m;
  const Vec3 eye{0, 0, 3};
  for (std::size_t i = 0; i < kNodes; ++i) {
    const Mat4 m = model * world(i);
    const std::array<float, 9> n = basaltNormalMatrix(m);
    const Vec3 c = m.transformPoint(toBasalt(s.centre[i]));
    r.checksum += n[0] + n[4] + n[8] + basalt::length(c - eye);
  }
  s.global = Mat4::rotationZ(0.1f) * Mat4::rotationY(0.2f) * Mat4::rotationX(0.3f) * s.global;
  return r;
}

template <typename M>
FrameResult glmFrame(Scene<M>& s) {
  const auto world = [&s](std::size_t i) {
    M m = s.local[i];
    for (int p = s.parent[i]; p >= 0; p = s.parent[static_cast<std::size_t>(p)])
      m = s.local[static_cast<std::size_t>(p)] * m;
    return m;
  };
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (std::size_t i = 0; i < kNodes; ++i) {
    const M w = world(i);
    for (int corner = 0; corner < 8; ++corner) {
      const glm::vec3 c{(corner & 1) ? s.boundsMax[i].x : s.boundsMin[i].x,
                        (corner & 2) ? s.boundsMax[i].y : s.boundsMin[i].y,
                        (corner & 4) ? s.boundsMax[i].z : s.boundsMin[i].z};
      const glm::vec3 p = glmPoint(w, c);
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
  }
  const glm::vec3 middle = (lo + hi) * 0.5f;
  const float scale = 2.0f / glm::length(hi - lo);
  const M normalisation = glm::translate(glm::scale(M(1.0f), Vec3Of<M>(scale)), glmVec<M>(-middle));
  const M model = s.global * s.localPosition * normalisation;
  const M view = glm::translate(M(1.0f), Vec3Of<M>(0, 0, -3));
  const M projection = M(glm::frustum(-0.9f, 0.9f, -0.5f, 0.5f, 1.0f, 5.0f));
  FrameResult r;
  const M viewProjection = projection * view;
  r.viewProjection = raw(viewProjection);
  const glm::vec3 eye{0, 0, 3};
  for (std::size_t i = 0; i < kNodes; ++i) {
    const M m = model * world(i);
    const std::array<float, 9> n = glmNormalMatrix(m);
    const glm::vec3 c = glmPoint(m, s.centre[i]);
    r.checksum += n[0] + n[4] + n[8] + glm::length(c - eye);
  }
  M spin = glm::rotate(M(1.0f), glm::radians(0.1f), Vec3Of<M>(0, 0, 1));
  spin = spin * glm::rotate(M(1.0f), glm::radians(0.2f), Vec3Of<M>(0, 1, 0));
  spin = spin * glm::rotate(M(1.0f), glm::radians(0.3f), Vec3Of<M>(1, 0, 0));
  s.global = spin * s.global;
  return r;
}

// ---- Agreement, checked before anything is timed --------------------------------------------------

/// The largest difference between two results, relative to the larger of 1 and the largest
/// magnitude in `reference`.
template <std::size_t N>
double difference(const std::array<float, N>& x, const std::array<float, N>& reference) {
  double scale = 1, worst = 0;
  for (float v : reference) scale = std::max(scale, static_cast<double>(std::fabs(v)));
  for (std::size_t i = 0; i < N; ++i)
    worst = std::max(worst, std::fabs(static_cast<double>(x[i]) - static_cast<double>(reference[i])));
  return worst / scale;
}

std::array<float, 3> raw3(const Vec3& v) { return {v.x, v.y, v.z}; }
std::array<float, 3> raw3(const glm::vec3& v) { return {v.x, v.y, v.z}; }

/// An exact-enough inverse: Gauss-Jordan with partial pivoting in long double.
std::array<long double, 16> referenceInverse(const std::array<float, 16>& m) {
  long double a[4][8] = {};
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) a[r][c] = m[static_cast<std::size_t>(c * 4 + r)];
    a[r][4 + r] = 1;
  }
  for (int col = 0; col < 4; ++col) {
    int pivot = col;
    for (int r = col + 1; r < 4; ++r)
      if (std::fabs(a[r][col]) > std::fabs(a[pivot][col])) pivot = r;
    for (int c = 0; c < 8; ++c) std::swap(a[col][c], a[pivot][c]);
    const long double p = a[col][col];
    for (int c = 0; c < 8; ++c) a[col][c] /= p;
    for (int r = 0; r < 4; ++r) {
      if (r == col) continue;
      const long double f = a[r][col];
      for (int c = 0; c < 8; ++c) a[r][c] -= f * a[col][c];
    }
  }
  std::array<long double, 16> inv{};
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) inv[static_cast<std::size_t>(c * 4 + r)] = a[r][4 + c];
  return inv;
}

double inverseError(const std::array<float, 16>& x, const std::array<long double, 16>& exact) {
  long double scale = 1, worst = 0;
  for (long double v : exact) scale = std::max(scale, std::fabs(v));
  for (std::size_t i = 0; i < 16; ++i) worst = std::max(worst, std::fabs(static_cast<long double>(x[i]) - exact[i]));
  return static_cast<double>(worst / scale);
}

struct Agreement {
  std::string name;
  double worst = 0;  // Basalt against GLM, relative
  double tolerance = 0;
};

struct InverseAccuracy {
  double basalt = 0, glm = 0, glmAligned = 0;
};

InverseAccuracy gModelInverse, gGeneralInverse;

/// Checks every operation on every input; prints the worst differences. False when any is
/// beyond its tolerance.
bool checkAgreement() {
  const Inputs& in = inputs();
  // Tolerances: a few float roundings for what both compute the same way, more for inverses
  // (GLM's is in float, Basalt's in double). A mismatch of conventions differs by order 1.
  std::vector<Agreement> rows = {
      {"multiply", 0, 1e-5},      {"inverse (model)", 0, 1e-4}, {"inverse (4x4)", 0, 1e-3},
      {"normal matrix", 0, 1e-4}, {"transform point", 0, 1e-5}, {"transform direction", 0, 1e-5},
      {"view setup", 0, 1e-5},    {"rotation", 0, 1e-5},        {"GLM SIMD = GLM", 0, 1e-4}};
  const auto note = [&rows](std::size_t row, double d) { rows[row].worst = std::max(rows[row].worst, d); };
  for (std::size_t i = 0; i < kCount; ++i) {
    const Mat4 a = basaltMat(in.a[i]), b = basaltMat(in.b[i]), g = basaltMat(in.general[i]);
    const auto ga = glmMat<glm::mat4>(in.a[i]), gb = glmMat<glm::mat4>(in.b[i]), gg = glmMat<glm::mat4>(in.general[i]);
    const auto sa = glmMat<GlmAligned>(in.a[i]), sb = glmMat<GlmAligned>(in.b[i]),
               sg = glmMat<GlmAligned>(in.general[i]);
    note(0, difference(raw(a * b), raw(ga * gb)));
    note(1, difference(raw(a.inverted()), raw(glm::inverse(ga))));
    note(2, difference(raw(g.inverted()), raw(glm::inverse(gg))));
    note(3, difference(basaltNormalMatrix(a), glmNormalMatrix(ga)));
    note(4, difference(raw3(a.transformPoint(in.points[i])), raw3(glmPoint(ga, glmVec(in.points[i])))));
    note(5, difference(raw3(a.transformDirection(in.directions[i])), raw3(glmDirection(ga, glmVec(in.directions[i])))));
    note(6, difference(raw(basaltViewSetup(in.views[i])), raw(glmViewSetup<glm::mat4>(in.views[i]))));
    note(7, difference(raw(basaltRotation(in.degrees[i], in.axes[i])),
                       raw(glmRotation<glm::mat4>(in.degrees[i], in.axes[i]))));
    note(8, difference(raw(sa * sb), raw(ga * gb)));
    note(8, difference(raw(glm::inverse(sg)), raw(glm::inverse(gg))));
    note(8, difference(raw3(glmPoint(sa, glmVec(in.points[i]))), raw3(glmPoint(ga, glmVec(in.points[i])))));

    const auto exactModel = referenceInverse(in.a[i]), exactGeneral = referenceInverse(in.general[i]);
    gModelInverse.basalt = std::max(gModelInverse.basalt, inverseError(raw(a.inverted()), exactModel));
    gModelInverse.glm = std::max(gModelInverse.glm, inverseError(raw(glm::inverse(ga)), exactModel));
    gModelInverse.glmAligned = std::max(gModelInverse.glmAligned, inverseError(raw(glm::inverse(sa)), exactModel));
    gGeneralInverse.basalt = std::max(gGeneralInverse.basalt, inverseError(raw(g.inverted()), exactGeneral));
    gGeneralInverse.glm = std::max(gGeneralInverse.glm, inverseError(raw(glm::inverse(gg)), exactGeneral));
    gGeneralInverse.glmAligned =
        std::max(gGeneralInverse.glmAligned, inverseError(raw(glm::inverse(sg)), exactGeneral));
  }
  // A whole frame, twice (the free-run rotation carries over).
  Scene<Mat4> bs = basaltScene();
  Scene<glm::mat4> gs = glmScene<glm::mat4>();
  Scene<GlmAligned> ss = glmScene<GlmAligned>();
  Agreement frameRow{"frame", 0, 1e-4};
  for (int f = 0; f < 2; ++f) {
    const FrameResult rb = basaltFrame(bs), rg = glmFrame(gs), rs = glmFrame(ss);
    frameRow.worst = std::max({frameRow.worst, difference(rb.viewProjection, rg.viewProjection),
                               difference(rs.viewProjection, rg.viewProjection),
                               std::fabs(static_cast<double>(rb.checksum - rg.checksum)) /
                                   std::max(1.0, std::fabs(static_cast<double>(rg.checksum))),
                               std::fabs(static_cast<double>(rs.checksum - rg.checksum)) /
                                   std::max(1.0, std::fabs(static_cast<double>(rg.checksum)))});
  }
  rows.push_back(frameRow);

  bool ok = true;
  std::printf("math: agreement of Basalt and GLM on %zu inputs each (largest difference relative to the result):\n",
              kCount);
  for (const Agreement& row : rows) {
    const bool good = row.worst <= row.tolerance;
    ok = ok && good;
    std::printf("math:   %-20s %.2e (tolerance %.0e) %s\n", row.name.c_str(), row.worst, row.tolerance,
                good ? "agree" : "DISAGREE");
  }
  return ok;
}

// ---- Benchmarks ----------------------------------------------------------------------------------

template <typename M>
std::vector<M> matrices(const std::vector<std::array<float, 16>>& raw16) {
  std::vector<M> out;
  for (const auto& m : raw16) {
    if constexpr (std::is_same_v<M, Mat4>) {
      out.push_back(basaltMat(m));
    } else {
      out.push_back(glmMat<M>(m));
    }
  }
  return out;
}

template <typename M>
void multiply(benchmark::State& state) {
  const std::vector<M> a = matrices<M>(inputs().a), b = matrices<M>(inputs().b);
  std::vector<M> out(kCount);
  for (auto _ : state) {
    for (std::size_t i = 0; i < kCount; ++i) out[i] = a[i] * b[i];
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
}

template <typename M>
void inverse(benchmark::State& state) {
  const std::vector<M> g = matrices<M>(inputs().general);
  std::vector<M> out(kCount);
  for (auto _ : state) {
    for (std::size_t i = 0; i < kCount; ++i) {
      if constexpr (std::is_same_v<M, Mat4>) {
        out[i] = g[i].inverted();
      } else {
        out[i] = glm::inverse(g[i]);
      }
    }
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
}

template <typename M>
void normalMatrix(benchmark::State& state) {
  const std::vector<M> a = matrices<M>(inputs().a);
  std::vector<std::array<float, 9>> out(kCount);
  for (auto _ : state) {
    for (std::size_t i = 0; i < kCount; ++i) {
      if constexpr (std::is_same_v<M, Mat4>) {
        out[i] = basaltNormalMatrix(a[i]);
      } else {
        out[i] = glmNormalMatrix(a[i]);
      }
    }
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
}

template <typename M, bool kPoint>
void transform(benchmark::State& state) {
  const std::vector<M> a = matrices<M>(inputs().a);
  const std::vector<Vec3>& v = kPoint ? inputs().points : inputs().directions;
  std::vector<glm::vec3> gv;
  for (const Vec3& x : v) gv.push_back(glmVec(x));
  std::vector<Vec3> out(kCount);
  std::vector<glm::vec3> gout(kCount);
  for (auto _ : state) {
    for (std::size_t i = 0; i < kCount; ++i) {
      if constexpr (std::is_same_v<M, Mat4>) {
        out[i] = kPoint ? a[i].transformPoint(v[i]) : a[i].transformDirection(v[i]);
      } else {
        gout[i] = kPoint ? glmPoint(a[i], gv[i]) : glmDirection(a[i], gv[i]);
      }
    }
    benchmark::DoNotOptimize(out.data());
    benchmark::DoNotOptimize(gout.data());
    benchmark::ClobberMemory();
  }
}

template <typename M>
void viewSetup(benchmark::State& state) {
  const std::vector<ViewInput>& v = inputs().views;
  std::vector<M> out(kCount);
  for (auto _ : state) {
    for (std::size_t i = 0; i < kCount; ++i) {
      if constexpr (std::is_same_v<M, Mat4>) {
        out[i] = basaltViewSetup(v[i]);
      } else {
        out[i] = glmViewSetup<M>(v[i]);
      }
    }
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
}

template <typename M>
void rotation(benchmark::State& state) {
  const Inputs& in = inputs();
  std::vector<M> out(kCount);
  for (auto _ : state) {
    for (std::size_t i = 0; i < kCount; ++i) {
      if constexpr (std::is_same_v<M, Mat4>) {
        out[i] = basaltRotation(in.degrees[i], in.axes[i]);
      } else {
        out[i] = glmRotation<M>(in.degrees[i], in.axes[i]);
      }
    }
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
}

template <typename M>
void frame(benchmark::State& state) {
  if constexpr (std::is_same_v<M, Mat4>) {
    Scene<Mat4> s = basaltScene();
    for (auto _ : state) {
      FrameResult r = basaltFrame(s);
      benchmark::DoNotOptimize(r);
    }
  } else {
    Scene<M> s = glmScene<M>();
    for (auto _ : state) {
      FrameResult r = glmFrame(s);
      benchmark::DoNotOptimize(r);
    }
  }
}

/// The operations, each as (figure name, what one operation is, operations per iteration).
struct Operation {
  const char* name;
  const char* what;
  std::size_t perIteration;
};
constexpr Operation kOperations[] = {
    {"multiply", "Mat4 * Mat4", kCount},
    {"inverse", "4x4 inverse", kCount},
    {"normalMatrix", "normal matrix", kCount},
    {"transformPoint", "point (divide by w)", kCount},
    {"transformDirection", "direction", kCount},
    {"viewSetup", "lookAt+perspective+frustum+ortho", kCount},
    {"rotation", "rotation about an axis", kCount},
    {"frame", "one frame, 256 nodes", 1},
};

void registerAll(double minTime) {
  const auto add = [minTime](const std::string& name, void (*fn)(benchmark::State&)) {
    benchmark::RegisterBenchmark(name.c_str(), fn)
        ->Unit(benchmark::kMicrosecond)
        ->MinTime(minTime)
        ->Repetitions(5)
        ->ReportAggregatesOnly(true);
  };
  add("multiply/Basalt", multiply<Mat4>);
  add("multiply/GLM", multiply<glm::mat4>);
  add("multiply/GLMsimd", multiply<GlmAligned>);
  add("inverse/Basalt", inverse<Mat4>);
  add("inverse/GLM", inverse<glm::mat4>);
  add("inverse/GLMsimd", inverse<GlmAligned>);
  add("normalMatrix/Basalt", normalMatrix<Mat4>);
  add("normalMatrix/GLM", normalMatrix<glm::mat4>);
  add("normalMatrix/GLMsimd", normalMatrix<GlmAligned>);
  add("transformPoint/Basalt", transform<Mat4, true>);
  add("transformPoint/GLM", transform<glm::mat4, true>);
  add("transformPoint/GLMsimd", transform<GlmAligned, true>);
  add("transformDirection/Basalt", transform<Mat4, false>);
  add("transformDirection/GLM", transform<glm::mat4, false>);
  add("transformDirection/GLMsimd", transform<GlmAligned, false>);
  add("viewSetup/Basalt", viewSetup<Mat4>);
  add("viewSetup/GLM", viewSetup<glm::mat4>);
  add("viewSetup/GLMsimd", viewSetup<GlmAligned>);
  add("rotation/Basalt", rotation<Mat4>);
  add("rotation/GLM", rotation<glm::mat4>);
  add("rotation/GLMsimd", rotation<GlmAligned>);
  add("frame/Basalt", frame<Mat4>);
  add("frame/GLM", frame<glm::mat4>);
  add("frame/GLMsimd", frame<GlmAligned>);
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  int kept = 1;
  for (int i = 1; i < argc; ++i) {
    if (std::string_view(argv[i]) == "--quick") {
      quick = true;
    } else {
      argv[kept++] = argv[i];
    }
  }
  argc = kept;
  if (!checkAgreement()) {
    std::printf("math: Basalt and GLM disagree (above); no figures\n");
    return 1;
  }
  std::printf(
      "math: inverse against a long double inverse (largest error relative to the largest element): model "
      "matrices Basalt %.1e, GLM %.1e, GLM SIMD %.1e; frustum * model Basalt %.1e, GLM %.1e, GLM SIMD %.1e\n\n",
      gModelInverse.basalt, gModelInverse.glm, gModelInverse.glmAligned, gGeneralInverse.basalt, gGeneralInverse.glm,
      gGeneralInverse.glmAligned);
  std::fflush(stdout);
  registerAll(quick ? 0.02 : 0.3);
  return basalt::bench::runBenchmarks(argc, argv, [](const basalt::bench::Medians& m) {
    // Google Benchmark names a benchmark's runs "name/min_time:…/repeats:…"; the function name is
    // the part before "/min_time".
    const auto find = [&m](const std::string& name) -> double {
      for (const auto& [key, value] : m)
        if (key.rfind(name + "/min_time", 0) == 0 || key == name) return value;
      return -1;
    };
    std::printf(
        "math: per operation, same inputs, same run (GLM: glm::mat4; GLM SIMD: glm::aligned_mat4 with "
        "GLM_FORCE_INTRINSICS)\n");
    std::printf("math:   %-20s %-34s %9s %9s %9s %12s %12s\n", "operation", "one operation", "Basalt", "GLM",
                "GLM SIMD", "Basalt/GLM", "Basalt/SIMD");
    double frameBasalt = -1;
    for (const Operation& op : kOperations) {
      const double b = find(std::string(op.name) + "/Basalt"), g = find(std::string(op.name) + "/GLM"),
                   s = find(std::string(op.name) + "/GLMsimd");
      if (b < 0 || g < 0 || s < 0) {
        std::printf("math:   %-20s no figures (a benchmark failed)\n", op.name);
        continue;
      }
      const double per = static_cast<double>(op.perIteration);
      const bool ns = op.perIteration > 1;
      const double unit = ns ? 1e9 : 1e6;
      std::printf("math:   %-20s %-34s %7.2f%s %7.2f%s %7.2f%s %12.2f %12.2f\n", op.name, op.what, b / per * unit,
                  ns ? "ns" : "us", g / per * unit, ns ? "ns" : "us", s / per * unit, ns ? "ns" : "us", b / g, b / s);
      if (std::string_view(op.name) == "frame") frameBasalt = b;
    }
    if (frameBasalt > 0) {
      std::printf("math: one frame's math for %zu nodes with Basalt: %.1f us, %.2f %% of a 60 Hz frame (16.7 ms)\n",
                  kNodes, frameBasalt * 1e6, frameBasalt * 60.0 * 100.0);
    }
  });
}
