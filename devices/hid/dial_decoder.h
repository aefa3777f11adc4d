#pragma once

/// \file
/// \brief Turning a dial box's input reports into Events: the Griffin PowerMate, the Contour
/// ShuttleXpress/ShuttlePRO, and any HID device whose report descriptor declares dials (Generic
/// Desktop Dial, Wheel, X/Y/Z, Rx/Ry/Rz, the System Multi-Axis Controller puck) and buttons.
/// Pure C++: the real backends and trace replay decode the same bytes the same way.

#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "devices/hid/report_descriptor.h"
#include "runtime/error.h"
#include "runtime/event.h"

namespace basalt::devices {

inline constexpr std::uint16_t kGriffinVendor = 0x077d;
inline constexpr std::uint16_t kPowerMateProduct = 0x0410;
inline constexpr std::uint16_t kContourVendor = 0x0b33;
inline constexpr std::uint16_t kShuttleProV1Product = 0x0010;
inline constexpr std::uint16_t kShuttleXpressProduct = 0x0020;
inline constexpr std::uint16_t kShuttleProV2Product = 0x0030;

/// \brief Counts per full turn Basalt assumes where a device does not say (a bindings gain
/// corrects a device that differs). The PowerMate has no detents; the ShuttleXpress jog wheel
/// has 10 per turn; a mouse wheel 24.
inline constexpr double kPowerMateCountsPerTurn = 96;
inline constexpr double kShuttleJogCountsPerTurn = 10;
inline constexpr double kWheelCountsPerTurn = 24;
inline constexpr double kDialCountsPerTurn = 3600;
inline constexpr double kAxisCountsPerTurn = 360;

enum class DialProfile : std::uint8_t { kPowerMate, kShuttle, kGenericHid };

std::string_view dialProfileName(DialProfile profile);

/// \brief Which profile a device gets: by vendor:product first, then by its descriptor.
DialProfile profileFor(std::uint16_t vendor, std::uint16_t product);

/// \brief How one decoded input reaches the event stream (for `basalt devices` and tests).
struct DialChannelInfo {
  std::uint32_t usage = 0;
  EventKind kind = EventKind::kDialDelta;
  double countsPerTurn = 0;
};

/// \brief Decodes one device's input reports into dial, shuttle and button events.
///
/// Keeps the last absolute values and button states between reports, so reports must be fed in
/// order; reset() forgets them (after a reopen). Not thread-safe: one reader at a time.
class DialDecoder {
 public:
  static constexpr std::size_t kMaxDials = 32;
  static constexpr std::size_t kMaxButtons = 64;
  static constexpr std::size_t kMaxEventsPerReport = 128;

  /// \brief A decoder for the device: PowerMate and Shuttle by id, any other by its descriptor
  /// (which must declare at least one dial, wheel or axis).
  [[nodiscard]] static Result<DialDecoder> create(std::uint16_t vendor, std::uint16_t product,
                                                  std::span<const std::uint8_t> descriptor,
                                                  std::string_view where = {});

  [[nodiscard]] DialProfile profile() const { return profile_; }
  [[nodiscard]] int dialCount() const { return static_cast<int>(dialCount_); }
  [[nodiscard]] int buttonCount() const { return static_cast<int>(buttonCount_); }
  [[nodiscard]] std::span<const DialChannelInfo> channels() const { return channelInfo_; }

  /// \brief Decodes one report (with its id byte when the descriptor uses ids) into `out`;
  /// returns how many events were written (device and time are left for the caller). Unknown
  /// report ids and short reports produce nothing. Never allocates.
  std::size_t decode(std::span<const std::uint8_t> report, std::span<Event> out);
  void reset();

 private:
  struct Channel {
    std::size_t field = 0;
    std::uint32_t element = 0;
    EventKind kind = EventKind::kDialDelta;
    std::uint16_t index = 0;
    double countsPerTurn = 1;
    bool wrapAbsolute = false;
    std::int64_t last = 0;
    bool haveLast = false;
  };
  struct ButtonChannel {
    std::size_t field = 0;
    std::uint32_t element = 0;  // variable fields
    bool array = false;
    std::uint16_t index = 0;
  };

  DialDecoder() = default;
  std::size_t decodePowerMate(std::span<const std::uint8_t> report, std::span<Event> out);
  std::size_t decodeShuttle(std::span<const std::uint8_t> report, std::span<Event> out);
  std::size_t decodeGeneric(std::span<const std::uint8_t> report, std::span<Event> out);

  DialProfile profile_ = DialProfile::kGenericHid;
  hid::ReportDescriptor descriptor_;
  std::vector<Channel> dials_;
  std::vector<ButtonChannel> buttons_;
  std::vector<DialChannelInfo> channelInfo_;
  std::size_t dialCount_ = 0;
  std::size_t buttonCount_ = 0;
  std::size_t variableButtons_ = 0;
  std::array<bool, kMaxButtons> pressed_{};
  std::array<bool, kMaxButtons> seen_{};  // scratch for array fields
  bool haveShuttleJog_ = false;
  std::uint8_t shuttleJog_ = 0;
  std::int8_t shuttleRing_ = 0;
};

/// \brief Consumer-page usages mapped to buttons (after the Button-page buttons), in this order:
/// Play/Pause, Scan Next, Scan Previous, Mute, Volume Up, Volume Down.
std::span<const std::uint16_t> consumerButtonUsages();

/// \brief Basalt's virtual dial box: 8 relative 16-bit Generic Desktop Dials in 0.1 degree
/// steps (3600 per turn) and 32 buttons, report id 1. Dial boxes without HID reports of their own
/// (the SGI serial box, synthetic dials) are recorded as this device.
const std::vector<std::uint8_t>& virtualDialBoxDescriptor();

/// \brief Encodes dial-delta and button events as reports of the virtual dial box descriptor
/// (a large turn becomes several reports). Other event kinds are not encoded.
class VirtualReportEncoder {
 public:
  using Sink = std::function<void(std::span<const std::uint8_t>)>;
  void encode(const Event& event, const Sink& sink);
  void reset() { buttons_ = 0; }

 private:
  std::uint32_t buttons_ = 0;
  double residue_[8] = {};  // sub-count remainders, so that slow turns are not lost
};

}  // namespace basalt::devices
