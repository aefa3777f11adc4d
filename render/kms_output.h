#pragma once

/// \file
/// \brief Fullscreen without a desktop: EGL on GBM, scanned out through KMS. Atomic modesetting
/// where the driver offers it, legacy page flips otherwise; never depends on native fence fds
/// (software rendering has none). Page-flip events pace the frame loop through paceFd().

#include <cstdint>
#include <memory>
#include <string>

#include "render/kms_modes.h"
#include "render/output.h"
#include "runtime/error.h"
#include "runtime/image.h"

namespace basalt::render {

/// \brief A KMS output: one connector, one CRTC, its primary plane.
///
/// Threading: the frame loop's thread. present() queues a page flip and returns; the flip's
/// event arrives on paceFd(), and readyForFrame() is false until it has.
class KmsOutput final : public Output {
 public:
  /// \brief Opens `request.drmDevice` (or the first card with a connected display), becomes DRM
  /// master, picks the connector and mode, and creates the EGL context on a GBM surface. Fails
  /// with a message that says what to do (another program holds the display, no display is
  /// connected, no such mode, ...). Set BASALT_KMS_LEGACY=1 to avoid atomic modesetting.
  static Result<std::unique_ptr<KmsOutput>> open(const OutputRequest& request);
  ~KmsOutput() override;
  KmsOutput(const KmsOutput&) = delete;
  KmsOutput& operator=(const KmsOutput&) = delete;

  [[nodiscard]] std::string_view kind() const override { return "kms"; }
  [[nodiscard]] Size size() const override;
  [[nodiscard]] std::string describe() const override;
  [[nodiscard]] Result<void> beginFrame() override;
  [[nodiscard]] Result<void> present() override;
  [[nodiscard]] int paceFd() const override;
  void onPaceReady() override;
  [[nodiscard]] bool readyForFrame() const override;
  [[nodiscard]] Result<void> setDisplayPower(bool on) override;

  /// \brief True when modesetting and flips go through the atomic API.
  [[nodiscard]] bool atomic() const;
  [[nodiscard]] const std::string& connectorName() const;
  [[nodiscard]] const KmsMode& mode() const;
  /// \brief Page flips completed since the modeset.
  [[nodiscard]] std::uint64_t flipsCompleted() const;
  /// \brief Waits (up to `timeoutMs`) for a pending flip to complete.
  [[nodiscard]] Result<void> waitForFlip(int timeoutMs);
  /// \brief Copies the buffer being scanned out now into `out` as RGBA8, top row first: what
  /// the display shows, read from the scan-out buffer itself.
  [[nodiscard]] Result<void> readScanout(Image& out);

  struct State;

 private:
  explicit KmsOutput(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

}  // namespace basalt::render
