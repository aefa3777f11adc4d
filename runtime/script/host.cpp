#include "runtime/script/host.h"

#include <fmt/format.h>
#include <fmt/std.h>

namespace basalt::script {

Result<void> OfflineHost::loadObject(const std::filesystem::path& file, runtime::Show& show) {
  (void)show;
  return fail(Errc::kUnavailable, "no model loader here (offline host)", file.string());
}

Result<void> OfflineHost::loadTexture(const std::filesystem::path& file, const std::string& name) {
  (void)name;
  return fail(Errc::kUnavailable, "no image loader here (offline host)", file.string());
}

Result<void> OfflineHost::saveImage(std::string_view name) {
  return fail(Errc::kUnavailable, fmt::format("no picture to save as '{}' here (offline host)", name));
}

Result<void> OfflineHost::accumulateJitterPass(int pass, int passes) {
  (void)pass;
  (void)passes;
  return fail(Errc::kUnavailable, "no picture to accumulate here (offline host)");
}

Result<void> OfflineHost::tv(const TvRequest& request) {
  (void)request;
  return fail(Errc::kUnavailable, "no movie player or camera here (offline host)");
}

}  // namespace basalt::script
