#pragma once

/// \file
/// \brief Choosing the KMS connector and display mode, as plain logic over what the driver
/// reports (no DRM headers): the connector the manifest names or the first connected one, and
/// the mode the manifest names or the connector's preferred one. Tested without a display.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "render/output.h"
#include "runtime/error.h"

namespace basalt::render {

/// \brief One mode a connector offers.
struct KmsMode {
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  double refresh = 0;  ///< Hz, from the pixel clock and totals
  bool preferred = false;
  bool interlaced = false;
};

/// \brief One connector as the driver reports it.
struct KmsConnector {
  std::uint32_t id = 0;
  std::string name;  ///< "HDMI-A-1", "DP-2", "Virtual-1": type name and index, as the kernel names them
  bool connected = false;
  std::vector<KmsMode> modes;
};

struct KmsSelection {
  std::size_t connector = 0;  ///< index into the connectors given
  std::size_t mode = 0;       ///< index into that connector's modes
};

/// \brief Picks the connector and mode. Errors list what there is to choose from.
[[nodiscard]] Result<KmsSelection> selectConnectorAndMode(std::span<const KmsConnector> connectors,
                                                          std::string_view wantedConnector,
                                                          const std::optional<ModeWish>& wantedMode);

/// \brief "1920x1080@60.00".
std::string describeMode(const KmsMode& mode);

}  // namespace basalt::render
