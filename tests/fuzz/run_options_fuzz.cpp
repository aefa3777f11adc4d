// Fuzzes `basalt run`'s option parsing: any argument list must give options or a usage error,
// never a crash or an exception. Input: NUL-separated arguments.

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "app/run_command.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string_view> args;
  std::size_t start = 0;
  for (std::size_t i = 0; i <= text.size(); ++i) {
    if (i == text.size() || text[i] == '\0') {
      args.push_back(text.substr(start, i - start));
      start = i + 1;
    }
  }
  auto options = basalt::kiosk::parseRunOptions(args);
  if (options && options->frames && *options->frames < 1) __builtin_trap();  // the parser's own contract
  return 0;
}
