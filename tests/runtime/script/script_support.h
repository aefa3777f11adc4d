#pragma once

/// \file
/// \brief Helpers for the script tier: a host that records what a script asked for, and short
/// ways to parse and run script text against a Show.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/script/host.h"
#include "runtime/script/interpreter.h"
#include "runtime/script/program.h"
#include "runtime/show/show.h"

namespace basalt::script::test {

/// \brief Records every request; textures, images and jitter passes succeed, objects load as a
/// two-part "boat" (parts "hull" and "mast"), the VCR and camera answer "unavailable".
class RecordingHost : public Host {
 public:
  [[nodiscard]] Result<void> loadObject(const std::filesystem::path& file, runtime::Show& show) override;
  [[nodiscard]] Result<void> loadTexture(const std::filesystem::path& file, const std::string& name) override;
  [[nodiscard]] Result<void> saveImage(std::string_view name) override;
  [[nodiscard]] Result<void> accumulateJitterPass(int pass, int passes) override;
  [[nodiscard]] Result<void> tv(const TvRequest& request) override;
  [[nodiscard]] bool renders(Feature feature) const override { return feature == Feature::kRendered; }

  std::vector<std::filesystem::path> objects;
  std::vector<std::string> textures;
  std::vector<std::string> images;
  std::vector<std::pair<int, int>> passes;
  std::vector<TvRequest> tvRequests;
  bool failObjects = false;  ///< loadObject fails (a missing or broken file)
};

/// \brief Parses `text` as "test.mdl".
Program parse(std::string_view text);

/// \brief A script run to its end against a show, with every message it gave.
struct Run {
  runtime::Show show = startupShow();
  RecordingHost host;
  std::vector<Diagnostic> messages;  ///< parse diagnostics first, then run-time ones
  std::vector<StepResult> steps;     ///< one per draw, then the last
  ObjectSource object;
  /// \brief Messages of one severity whose text contains `needle`.
  [[nodiscard]] std::size_t count(Severity severity, std::string_view needle = {}) const;
};

/// \brief Runs `text` to its end (or `maxSteps` steps), advancing the show one frame per draw as
/// the frame loop does.
Run run(std::string_view text, std::size_t maxSteps = 100000);

/// \brief A mesh with two parts, "hull" and "mast": what RecordingHost loads.
std::shared_ptr<const runtime::Mesh> makeBoat();

}  // namespace basalt::script::test
