#include "kiosk/osc/osc_router.h"

#include <lo/lo.h>

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "runtime/log.h"

namespace basalt::kiosk {

namespace {

// At most this many addresses and senders are logged one by one; past that, one line says so.
constexpr std::size_t kMaxLogged = 256;

std::string normalSender(const std::string& sender) {
  // An IPv4 sender on a dual-stack socket reads as ::ffff:a.b.c.d.
  constexpr std::string_view kMapped = "::ffff:";
  if (sender.starts_with(kMapped) && sender.find('.') != std::string::npos) return sender.substr(kMapped.size());
  return sender;
}

}  // namespace

std::string_view oscOutcomeName(OscOutcome outcome) {
  switch (outcome) {
    case OscOutcome::kActed: return "acted";
    case OscOutcome::kHeld: return "held";
    case OscOutcome::kUnmatched: return "unmatched";
    case OscOutcome::kWrongTypes: return "wrong_types";
    case OscOutcome::kBadArgument: return "bad_argument";
    case OscOutcome::kRefusedSender: return "refused_sender";
    case OscOutcome::kRateLimited: return "rate_limited";
  }
  return "unmatched";
}

OscRouter::OscRouter(const OscSpec& spec)
    : spec_(spec), limiter_(spec.messagesPerSecond), lastPosition_(spec.bindings.size()) {}

double OscRouter::scale(double value, const std::array<double, 2>& input,
                        const std::optional<std::array<double, 2>>& range) {
  if (!range) return value;
  const double low = std::min(input[0], input[1]);
  const double high = std::max(input[0], input[1]);
  const double t = (std::clamp(value, low, high) - input[0]) / (input[1] - input[0]);
  return (*range)[0] + t * ((*range)[1] - (*range)[0]);
}

bool OscRouter::typesFit(const std::vector<OscArgument>& arguments, std::string_view types) {
  if (arguments.size() != types.size()) return false;
  for (std::size_t i = 0; i < types.size(); ++i) {
    const OscArgument& a = arguments[i];
    if (types[i] == 'f' && !(a.isNumber() && std::isfinite(a.number))) return false;
    if (types[i] == 's' && !a.isString()) return false;
  }
  return true;
}

std::string OscRouter::stringProblem(std::string_view text) {
  if (text.empty()) return "an empty string";
  if (text.size() > kOscMaxStringBytes) return fmt::format("a string of more than {} bytes", kOscMaxStringBytes);
  for (const char c : text) {
    // One word of a LAVA command: printable, no space, no quote or comment that would change
    // how the rest of the command reads.
    if (c <= ' ' || c > '~' || c == '"' || c == '\'' || c == '#' || c == ';' || c == '\\') {
      return "a string with spaces, quotes, ';', '#' or characters that are not printable ASCII";
    }
  }
  return {};
}

bool OscRouter::matches(const std::string& address, const std::string& pattern) {
  if (pattern.find_first_of("?*[]{}") == std::string::npos) return address == pattern;
  return lo_pattern_match(address.c_str(), pattern.c_str()) != 0;
}

OscOutcome OscRouter::refuse(OscOutcome outcome, const OscMessage& message, std::string why, OscRouted& routed) {
  switch (outcome) {
    case OscOutcome::kUnmatched: ++figures_.unmatched; break;
    case OscOutcome::kWrongTypes: ++figures_.wrongTypes; break;
    case OscOutcome::kBadArgument: ++figures_.badArgument; break;
    case OscOutcome::kRefusedSender: ++figures_.refusedSender; break;
    case OscOutcome::kRateLimited: ++figures_.rateLimited; break;
    case OscOutcome::kActed:
    case OscOutcome::kHeld: break;
  }
  // Once per address (per sender for senders and rates): a flood says it once, not per message.
  const bool bySender = outcome == OscOutcome::kRefusedSender || outcome == OscOutcome::kRateLimited;
  const std::string key = fmt::format("{} {}", oscOutcomeName(outcome), bySender ? message.sender : message.address);
  if (logged_.size() < kMaxLogged) {
    if (logged_.insert(key).second) {
      log::warn(kLogOsc, "OSC {} {} from {}: {}; not acted on (said once per {})", message.address, message.typeTags(),
                message.sender, why, bySender ? "sender" : "address");
    }
  } else if (!loggedFull_ && !logged_.contains(key)) {
    loggedFull_ = true;
    log::warn(kLogOsc, "more than {} OSC addresses and senders were refused; the rest are counted, not logged",
              kMaxLogged);
  }
  routed.outcome = outcome;
  routed.why = std::move(why);
  return outcome;
}

OscRouted OscRouter::route(const OscMessage& message, Nanos now) {
  ++figures_.received;
  OscRouted routed;
  const std::string sender = normalSender(message.sender);
  if (!spec_.allow.empty() && std::ranges::find(spec_.allow, sender) == spec_.allow.end()) {
    refuse(OscOutcome::kRefusedSender, message, "the sender is not in osc.allow", routed);
    return routed;
  }
  if (message.address.starts_with(kOscTrackerPrefix)) {
    if (!tracker_) {
      refuse(OscOutcome::kUnmatched, message, "no tracker device takes /tracker/ messages in this show", routed);
    } else if (tracker_->take(message)) {
      routed.outcome = OscOutcome::kHeld;
    } else {
      refuse(OscOutcome::kWrongTypes, message, "the tracker device cannot use it", routed);
    }
    return routed;
  }
  if (!limiter_.allow(sender, now)) {
    refuse(OscOutcome::kRateLimited, message,
           fmt::format("over osc.messages_per_second ({} a second, bursts of {})", limiter_.rate(), limiter_.burst()),
           routed);
    return routed;
  }
  bool matched = false;
  bool held = false;
  OscOutcome failed = OscOutcome::kUnmatched;
  std::string why;
  for (std::size_t i = 0; i < spec_.bindings.size(); ++i) {
    const OscBindingSpec& b = spec_.bindings[i];
    if (!matches(b.address, message.address)) continue;
    matched = true;
    OscOutcome f = OscOutcome::kUnmatched;
    if (!control(b, i, message, routed, f)) {
      if (f == OscOutcome::kHeld) {
        held = true;
      } else {
        failed = f;
        why = std::move(routed.why);
      }
    }
  }
  if (!routed.controls.empty()) {
    ++figures_.acted;
    routed.outcome = OscOutcome::kActed;
    return routed;
  }
  if (held) {
    routed.outcome = OscOutcome::kHeld;
    return routed;
  }
  if (!matched) {
    refuse(OscOutcome::kUnmatched, message, "no [[osc.bind]] has this address", routed);
    return routed;
  }
  refuse(failed, message, std::move(why), routed);
  return routed;
}

bool OscRouter::control(const OscBindingSpec& b, std::size_t index, const OscMessage& message, OscRouted& routed,
                        OscOutcome& failed) {
  if (!typesFit(message.arguments, b.types)) {
    failed = OscOutcome::kWrongTypes;
    routed.why =
        fmt::format("the types are {} where the binding (show.toml:{}) takes ,{}", message.typeTags(), b.line, b.types);
    return false;
  }
  ControlRequest request;
  switch (b.what) {
    case OscDo::kDial: {
      const double value = scale(message.arguments[0].number, b.input, b.range);
      double amount = value;
      if (b.absolute) {
        std::optional<double>& last = lastPosition_[index];
        // A fader: the first position says where it stands; later ones move by their change.
        amount = last ? value - *last : 0;
        last = value;
      }
      if (amount == 0) {
        failed = OscOutcome::kHeld;
        return false;
      }
      request.kind = ControlKind::kAction;
      request.action = b.action;
      request.amount = static_cast<float>(amount);
      break;
    }
    case OscDo::kNext:
    case OscDo::kPrevious:
    case OscDo::kReload:
    case OscDo::kResetView:
      // A button sends 1 when pressed and 0 when let go: it acts when pressed.
      if (!message.arguments.empty() && message.arguments[0].number < 0.5) {
        failed = OscOutcome::kHeld;
        return false;
      }
      request.kind = b.what == OscDo::kNext       ? ControlKind::kNext
                     : b.what == OscDo::kPrevious ? ControlKind::kPrevious
                     : b.what == OscDo::kReload   ? ControlKind::kReload
                                                  : ControlKind::kResetView;
      break;
    case OscDo::kCommand: {
      std::string command;
      command.reserve(b.command.size() + 16);
      for (std::size_t i = 0; i < b.command.size(); ++i) {
        const char c = b.command[i];
        if (c == '$' && i + 1 < b.command.size() && b.command[i + 1] >= '1' && b.command[i + 1] <= '8') {
          const auto n = static_cast<std::size_t>(b.command[i + 1] - '1');
          ++i;
          const OscArgument& a = message.arguments[n];
          if (a.isString()) {
            if (auto problem = stringProblem(a.text); !problem.empty()) {
              failed = OscOutcome::kBadArgument;
              routed.why = fmt::format("argument {} is {}, which the command cannot take", n + 1, problem);
              return false;
            }
            command += a.text;
          } else {
            command += fmt::format("{}", scale(a.number, b.input, b.range));
          }
          continue;
        }
        command += c;
      }
      if (command.size() > kOscMaxCommandBytes) {
        failed = OscOutcome::kBadArgument;
        routed.why =
            fmt::format("the command would be {} bytes; a command is at most {}", command.size(), kOscMaxCommandBytes);
        return false;
      }
      request.kind = ControlKind::kRunCommand;
      request.argument = std::move(command);
      break;
    }
  }
  routed.controls.push_back(std::move(request));
  routed.bindings.push_back(&b);
  return true;
}

}  // namespace basalt::kiosk
