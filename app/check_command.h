#pragma once

/// \file
/// \brief `basalt check FILE...`: finds every error in the files a show is made of, without
/// running anything. Each kind of file has its own checker, chosen by the file's extension
/// (kiosk/manifest/content_check.h holds the table; each checker lives in its own file).

#include <span>
#include <string_view>

namespace basalt::kiosk {

std::string_view checkUsage();
/// \brief `basalt check ...`: 0 when every file is free of errors, 1 when one has errors or
/// cannot be read, 2 for usage errors.
int checkMain(std::span<const std::string_view> args);

}  // namespace basalt::kiosk
