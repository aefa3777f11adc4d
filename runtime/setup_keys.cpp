#include "runtime/setup_keys.h"

#include <array>
#include <string>
#include <utility>

namespace basalt::runtime {
namespace {
// Linux input key codes (linux/input-event-codes.h), the values kKey events carry.
enum Key : std::uint16_t {
  kKeyEsc = 1,
  kKeyW = 17,
  kKeyT = 20,
  kKeyP = 25,
  kKeyLeftCtrl = 29,
  kKeyS = 31,
  kKeyD = 32,
  kKeyF = 33,
  kKeyL = 38,
  kKeyLeftShift = 42,
  kKeyC = 46,
  kKeyN = 49,
  kKeyRightShift = 54,
  kKeyRightCtrl = 97,
};

constexpr std::array<std::pair<SetupToggle, std::string_view>, 13> kNames{{
    {SetupToggle::kControlMode, "control"},
    {SetupToggle::kCaveMode, "cave"},
    {SetupToggle::kStereo, "stereo"},
    {SetupToggle::kFog, "fog"},
    {SetupToggle::kSmoothShading, "smooth"},
    {SetupToggle::kLighting, "lighting"},
    {SetupToggle::kFilled, "filled"},
    {SetupToggle::kPoints, "points"},
    {SetupToggle::kWireframe, "wireframe"},
    {SetupToggle::kNormals, "normals"},
    {SetupToggle::kLightTokens, "light-tokens"},
    {SetupToggle::kPause, "pause"},
    {SetupToggle::kExit, "exit"},
}};

std::string onOff(std::string_view what, bool on) { return std::string(what) + (on ? " on" : " off"); }

}  // namespace

std::string_view setupToggleName(SetupToggle toggle) {
  for (const auto& [t, name] : kNames) {
    if (t == toggle) return name;
  }
  return "?";
}

std::optional<SetupToggle> parseSetupToggle(std::string_view name) {
  for (const auto& [t, n] : kNames) {
    if (n == name) return t;
  }
  return std::nullopt;
}

std::optional<SetupToggle> SetupToggles::key(const Event& event) {
  if (event.kind != EventKind::kKey) return std::nullopt;
  const bool down = event.value != 0;
  switch (event.index) {
    case kKeyLeftShift: leftShift_ = down; return std::nullopt;
    case kKeyRightShift: rightShift_ = down; return std::nullopt;
    case kKeyLeftCtrl: leftCtrl_ = down; return std::nullopt;
    case kKeyRightCtrl: rightCtrl_ = down; return std::nullopt;
    default: break;
  }
  // A press only: auto-repeat (value 2) would toggle back and forth while the key is held.
  if (event.value != 1) return std::nullopt;
  const bool shift = leftShift_ || rightShift_;
  const bool ctrl = leftCtrl_ || rightCtrl_;
  if (ctrl) {
    switch (event.index) {
      case kKeyC: return SetupToggle::kControlMode;
      case kKeyD: return controlMode_ ? std::optional(SetupToggle::kLightTokens) : std::nullopt;
      case kKeyL: return controlMode_ ? std::optional(SetupToggle::kLighting) : std::nullopt;
      default: return std::nullopt;
    }
  }
  if (!controlMode_) return std::nullopt;
  switch (event.index) {
    case kKeyC: return shift ? std::nullopt : std::optional(SetupToggle::kCaveMode);
    case kKeyT: return shift ? std::nullopt : std::optional(SetupToggle::kStereo);
    case kKeyF: return shift ? SetupToggle::kFog : SetupToggle::kFilled;
    case kKeyS: return shift ? std::nullopt : std::optional(SetupToggle::kSmoothShading);  // S: base side
    case kKeyN: return shift ? std::nullopt : std::optional(SetupToggle::kNormals);
    case kKeyP: return shift ? SetupToggle::kPoints : SetupToggle::kPause;
    case kKeyW: return shift ? std::nullopt : std::optional(SetupToggle::kWireframe);
    case kKeyEsc: return SetupToggle::kExit;
    default: return std::nullopt;
  }
}

std::string SetupToggles::apply(SetupToggle toggle, Show& show) {
  switch (toggle) {
    case SetupToggle::kControlMode: controlMode_ = !controlMode_; return onOff("control mode", controlMode_);
    case SetupToggle::kCaveMode: return "cave mode";
    case SetupToggle::kExit: return "exit";
    case SetupToggle::kStereo:
      show.global().stereo = !show.global().stereo;
      return onOff("stereo", show.global().stereo);
    case SetupToggle::kFog: {
      Fog& fog = show.fog();
      if (fog.mode != FogMode::kNone) {
        fogWas_ = fog.mode;
        fog.mode = FogMode::kNone;
      } else {
        fog.mode = fogWas_;
      }
      return onOff("fog", fog.mode != FogMode::kNone);
    }
    case SetupToggle::kLighting: {
      Illumination now = show.globalStyle().front.illumination;
      if (now != Illumination::kNone) {
        lightingWas_ = now;
        now = Illumination::kNone;
      } else {
        now = lightingWas_;
      }
      show.editGlobalStyle([&](PartStyle& s) { s.front.illumination = now; });
      return onOff("lighting", now != Illumination::kNone);
    }
    case SetupToggle::kSmoothShading: {
      // Smooth: lit at each vertex and interpolated; flat: one lighting calculation per polygon.
      const bool smooth = show.globalStyle().front.illumination != Illumination::kPerVertex;
      show.editGlobalStyle(
          [&](PartStyle& s) { s.front.illumination = smooth ? Illumination::kPerVertex : Illumination::kPerFacet; });
      return onOff("smooth shading", smooth);
    }
    case SetupToggle::kFilled:
    case SetupToggle::kPoints:
    case SetupToggle::kWireframe: {
      const PrimType type = toggle == SetupToggle::kFilled   ? PrimType::kSolid
                            : toggle == SetupToggle::kPoints ? PrimType::kMarkers
                                                             : PrimType::kWireframe;
      show.editGlobalStyle([&](PartStyle& s) { s.render.primType = type; });
      return std::string("surfaces drawn as ") + std::string(setupToggleName(toggle));
    }
    case SetupToggle::kNormals:
      normals_ = !normals_;
      return onOff("normals", normals_) + " (Basalt does not draw surface normals)";
    case SetupToggle::kLightTokens:
      lightTokens_ = !lightTokens_;
      return onOff("light tokens", lightTokens_) + " (Basalt does not draw light tokens)";
    case SetupToggle::kPause:
      if (paused_) {
        show.motion() = *paused_;
        paused_.reset();
        return "pause off";
      }
      paused_ = show.motion();
      show.motion().globalFreeRun = false;
      show.motion().localFreeRun = false;
      return "pause on";
  }
  return {};
}

}  // namespace basalt::runtime
