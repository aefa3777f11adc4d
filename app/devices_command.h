#pragma once

/// \file
/// \brief `basalt devices`: what is connected, what Basalt would use each device as, and why a
/// device cannot be opened.

#include <span>
#include <string_view>

namespace basalt::kiosk {

std::string_view devicesUsage();
int devicesMain(std::span<const std::string_view> args);

}  // namespace basalt::kiosk
