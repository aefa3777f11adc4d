#include "render/kms_modes.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include <fmt/format.h>

namespace basalt::render {

namespace {

bool sameName(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

std::string connectorList(std::span<const KmsConnector> connectors) {
  std::string out;
  for (const KmsConnector& c : connectors) {
    if (!out.empty()) out += ", ";
    out += fmt::format("{} ({})", c.name, c.connected ? "connected" : "nothing connected");
  }
  return out.empty() ? "none" : out;
}

std::string modeList(const KmsConnector& c) {
  std::string out;
  for (const KmsMode& m : c.modes) {
    if (!out.empty()) out += ", ";
    out += describeMode(m);
    if (m.preferred) out += " (preferred)";
  }
  return out.empty() ? "none" : out;
}

/// Better of two modes when nothing is asked for: progressive, larger, then faster.
bool better(const KmsMode& a, const KmsMode& b) {
  if (a.interlaced != b.interlaced) return !a.interlaced;
  const std::uint64_t areaA = std::uint64_t{a.width} * a.height;
  const std::uint64_t areaB = std::uint64_t{b.width} * b.height;
  if (areaA != areaB) return areaA > areaB;
  return a.refresh > b.refresh;
}

}  // namespace

std::string describeMode(const KmsMode& mode) {
  return fmt::format("{}x{}@{:.2f}{}", mode.width, mode.height, mode.refresh, mode.interlaced ? "i" : "");
}

Result<KmsSelection> selectConnectorAndMode(std::span<const KmsConnector> connectors, std::string_view wantedConnector,
                                            const std::optional<ModeWish>& wantedMode) {
  KmsSelection selection;
  if (!wantedConnector.empty()) {
    const auto it = std::find_if(connectors.begin(), connectors.end(),
                                 [&](const KmsConnector& c) { return sameName(c.name, wantedConnector); });
    if (it == connectors.end()) {
      return fail(Errc::kNotFound, fmt::format("there is no connector '{}'; this card has: {}", wantedConnector,
                                               connectorList(connectors)));
    }
    if (!it->connected) {
      return fail(Errc::kUnavailable, fmt::format("nothing is connected to {}; check the cable and the display's "
                                                  "power (connectors: {})",
                                                  it->name, connectorList(connectors)));
    }
    selection.connector = static_cast<std::size_t>(it - connectors.begin());
  } else {
    const auto it =
        std::find_if(connectors.begin(), connectors.end(), [](const KmsConnector& c) { return c.connected; });
    if (it == connectors.end()) {
      return fail(Errc::kUnavailable, fmt::format("no display is connected (connectors: {}); check the cable and "
                                                  "the display's power",
                                                  connectorList(connectors)));
    }
    selection.connector = static_cast<std::size_t>(it - connectors.begin());
  }
  const KmsConnector& c = connectors[selection.connector];
  if (c.modes.empty()) {
    return fail(Errc::kUnavailable, fmt::format("{} reports no modes; the display's EDID may be unreadable", c.name));
  }
  std::optional<std::size_t> best;
  for (std::size_t i = 0; i < c.modes.size(); ++i) {
    const KmsMode& m = c.modes[i];
    if (wantedMode) {
      if (m.width != wantedMode->width || m.height != wantedMode->height) continue;
      if (wantedMode->refresh > 0 && std::abs(m.refresh - wantedMode->refresh) > 0.5) continue;
      // Among matching modes: the preferred one, else progressive and fastest.
      if (!best || (m.preferred && !c.modes[*best].preferred) ||
          (m.preferred == c.modes[*best].preferred && better(m, c.modes[*best]))) {
        best = i;
      }
    } else if (m.preferred && !m.interlaced) {
      best = i;
      break;
    } else if (!best || better(m, c.modes[*best])) {
      best = i;
    }
  }
  if (!best) {
    return fail(
        Errc::kNotFound,
        fmt::format("{} has no mode {}x{}{}; it offers: {}", c.name, wantedMode->width, wantedMode->height,
                    wantedMode->refresh > 0 ? fmt::format("@{}", wantedMode->refresh) : std::string(), modeList(c)));
  }
  selection.mode = *best;
  return selection;
}

}  // namespace basalt::render
