#include "runtime/head_tracking.h"

#include <cmath>
#include <numbers>

namespace basalt::runtime {

Vec3 headRight(const Vec3& rotationDegrees) {
  const Mat4 r =
      Mat4::rotationX(rotationDegrees.x) * Mat4::rotationY(rotationDegrees.y) * Mat4::rotationZ(rotationDegrees.z);
  return normalize(r.transformDirection({1, 0, 0}));
}

double HeadSmoother::alpha(double cutoffHz, double dt) {
  // A first-order low pass sampled at dt: tau = 1 / (2 pi fc), weight dt / (tau + dt).
  const double tau = 1.0 / (2.0 * std::numbers::pi * cutoffHz);
  return dt / (tau + dt);
}

const HeadPose& HeadSmoother::add(Nanos time, const Vec3& position, const Vec3& right) {
  const Vec3 unitRight = normalize(right);
  const double dt = std::chrono::duration<double>(time - last_).count();
  if (!primed_ || config_.kind == HeadSmoothing::Kind::kOff) {
    pose_.position = position;
    pose_.right = unitRight;
    pose_.tracked = true;
    pose_.sampleTime = time;
    speed_ = {};
    last_ = time;
    primed_ = true;
    return pose_;
  }
  // A sample no newer than the one before (a repeated stamp) carries no time to weigh it by.
  if (!(dt > 0)) return pose_;
  float a = 0;
  if (config_.kind == HeadSmoothing::Kind::kExponential) {
    const double tau = std::chrono::duration<double>(config_.timeConstant).count();
    a = static_cast<float>(tau > 0 ? 1.0 - std::exp(-dt / tau) : 1.0);
  } else {
    const Vec3 rawSpeed = (position - pose_.position) / static_cast<float>(dt);
    const auto ad = static_cast<float>(alpha(config_.derivativeCutoff, dt));
    speed_ = speed_ + (rawSpeed - speed_) * ad;
    const double cutoff = config_.minCutoff + config_.beta * static_cast<double>(length(speed_));
    a = static_cast<float>(alpha(cutoff, dt));
  }
  pose_.position = pose_.position + (position - pose_.position) * a;
  pose_.right = normalize(pose_.right + (unitRight - pose_.right) * a);
  pose_.tracked = true;
  pose_.sampleTime = time;
  last_ = time;
  return pose_;
}

}  // namespace basalt::runtime
