#pragma once

/// \file
/// \brief What an OSC message does: the sender checked against `osc.allow` and the rate limit,
/// the address matched against the `[[osc.bind]]` addresses (OSC 1.0 patterns, liblo's matcher),
/// the arguments checked against the binding's types and scaled, and a `ControlRequest` made for
/// the frame loop (the same request the HTTP controls make). Messages under `/tracker/` go to a
/// tracker sink instead (none yet: see kiosk/osc/README.md, "Trackers").

#include <array>
#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "kiosk/manifest/manifest.h"
#include "kiosk/osc/osc_message.h"
#include "kiosk/status/rate_limiter.h"
#include "kiosk/status/status_board.h"

namespace basalt::kiosk {

/// \brief The address prefix kept for tracker devices.
inline constexpr std::string_view kOscTrackerPrefix = "/tracker/";

/// \brief Where messages under `/tracker/` go: the seam for a tracker device kind. `take` runs on
/// the OSC input's thread for each such message from an allowed sender (no rate limit: a tracker
/// sends every frame); it must not block (push into a bounded queue and wake the loop, as a
/// device reader does) and returns false for a message it cannot use (counted `wrong_types`).
class OscTrackerSink {
 public:
  virtual ~OscTrackerSink() = default;
  virtual bool take(const OscMessage& message) = 0;
};

/// \brief What became of one message.
enum class OscOutcome : std::uint8_t {
  kActed,          ///< one or more controls made
  kHeld,           ///< understood, nothing to do: a button let go, a fader's first position, a tracker's
  kUnmatched,      ///< no binding's address
  kWrongTypes,     ///< the arguments are not the binding's types
  kBadArgument,    ///< a string a command cannot take, or a command over its length
  kRefusedSender,  ///< not in osc.allow
  kRateLimited,    ///< over osc.messages_per_second
};

/// \brief The controls one message made (a pattern may match several bindings).
struct OscRouted {
  OscOutcome outcome = OscOutcome::kUnmatched;
  std::vector<ControlRequest> controls;         ///< without their reply objects
  std::vector<const OscBindingSpec*> bindings;  ///< the binding of each control
  std::string why;                              ///< what was wrong, for the log
};

/// \brief The longest command a message may make: the HTTP control's bound.
inline constexpr std::size_t kOscMaxCommandBytes = 1024;
/// \brief The longest string argument a command takes.
inline constexpr std::size_t kOscMaxStringBytes = 256;

/// \brief Routes messages to controls. Threading: the OSC input's thread only (route() keeps the
/// faders' last positions, the counts and the addresses already logged).
class OscRouter {
 public:
  explicit OscRouter(const OscSpec& spec);

  /// \brief What `message` does, at `now` (for the rate limit). Counts it, and logs the first
  /// refusal of each address (of each sender for senders and rates).
  [[nodiscard]] OscRouted route(const OscMessage& message, Nanos now);
  /// \brief Messages under /tracker/ go to `sink` (borrowed; null: none, they count as unmatched).
  void setTrackerSink(OscTrackerSink* sink) { tracker_ = sink; }

  /// \brief Counts packets the input could not take apart, and controls the queue refused.
  void countMalformed(std::size_t n) { figures_.malformed += n; }
  /// `messageLost`: none of the message's controls got into the queue, so it did not act after all.
  void countQueueFull(bool messageLost) {
    ++figures_.queueFull;
    if (messageLost && figures_.acted > 0) --figures_.acted;
  }
  [[nodiscard]] const OscFigures& figures() const { return figures_; }

  /// \brief `value` read in `input` (clamped to it) and scaled into `range`; unchanged without a range.
  [[nodiscard]] static double scale(double value, const std::array<double, 2>& input,
                                    const std::optional<std::array<double, 2>>& range);
  /// \brief Whether a message's arguments fit `types` ('f' a finite number, 's' a string).
  [[nodiscard]] static bool typesFit(const std::vector<OscArgument>& arguments, std::string_view types);
  /// \brief Why `text` cannot stand in a command as one word, or "".
  [[nodiscard]] static std::string stringProblem(std::string_view text);
  /// \brief Whether `pattern` (a message's address, OSC 1.0 patterns allowed) matches `address`.
  [[nodiscard]] static bool matches(const std::string& address, const std::string& pattern);

 private:
  OscOutcome refuse(OscOutcome outcome, const OscMessage& message, std::string why, OscRouted& routed);
  /// Makes the control of `binding`; false (and `why`) when the message cannot make it.
  bool control(const OscBindingSpec& binding, std::size_t index, const OscMessage& message, OscRouted& routed,
               OscOutcome& failed);

  const OscSpec spec_;
  RateLimiter limiter_;
  OscTrackerSink* tracker_ = nullptr;
  OscFigures figures_;
  std::vector<std::optional<double>> lastPosition_;  // absolute bindings: the previous scaled value
  std::set<std::string> logged_;                     // "outcome address" already logged
  bool loggedFull_ = false;
};

/// \brief "unmatched", "wrong_types", ... (the label of basalt_osc_messages_total).
[[nodiscard]] std::string_view oscOutcomeName(OscOutcome outcome);

}  // namespace basalt::kiosk
