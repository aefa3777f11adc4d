#pragma once

/// \file
/// \brief `basalt record`: taps live devices into a trace folder (DESIGN.md §5).

#include <span>
#include <string_view>

namespace basalt::kiosk {

std::string_view recordUsage();
int recordMain(std::span<const std::string_view> args);

}  // namespace basalt::kiosk
