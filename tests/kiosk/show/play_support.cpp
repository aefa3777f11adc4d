#include "play_support.h"

#include <gtest/gtest.h>

#include "runtime/event_loop.h"
#include "runtime/script/interpreter.h"

namespace basalt::script::test {

namespace {

/// Keeps chosen frames. Added after the ScriptPlayer: by beforeDraw() the Show holds what this
/// frame draws (the player ran the script up to this frame's draw), and by afterDraw() the
/// picture is in the framebuffer.
class Keeper final : public kiosk::FrameParticipant {
 public:
  Keeper(const runtime::Show& show, const kiosk::ScriptPlayer& player, const std::set<std::int64_t>& state,
         const std::set<std::int64_t>& images, std::vector<KeptFrame>& out)
      : show_(show), player_(player), state_(state), images_(images), out_(out) {}

  Result<void> beforeDraw(const kiosk::FrameContext& frame) override {
    if (state_.count(frame.frame) || images_.count(frame.frame)) {
      out_.push_back({frame.frame, show_, {}, player_.currentStep()});
    }
    return {};
  }
  Result<void> afterDraw(const kiosk::FrameContext& frame, render::Output& output) override {
    if (!images_.count(frame.frame)) return {};
    return output.readBack(out_.back().image);
  }

 private:
  const runtime::Show& show_;
  const kiosk::ScriptPlayer& player_;
  const std::set<std::int64_t>& state_;
  const std::set<std::int64_t>& images_;
  std::vector<KeptFrame>& out_;
};

}  // namespace

const KeptFrame& Played::at(std::int64_t frame) const {
  for (const KeptFrame& f : frames) {
    if (f.frame == frame) return f;
  }
  ADD_FAILURE() << "frame " << frame << " was not kept";
  static const KeptFrame kNone;
  return kNone;
}

std::size_t Played::count(Severity severity, std::string_view needle) const {
  std::size_t n = 0;
  for (const Diagnostic& d : messages) {
    if (d.severity == severity && d.message.find(needle) != std::string::npos) ++n;
  }
  return n;
}

std::unique_ptr<Stage> Stage::open(render::Size size, std::string& why) {
  auto output = render::createHeadlessOutput(size);
  if (!output) {
    why = output.error().describe();
    return nullptr;
  }
  auto renderer = render::Renderer::create();
  if (!renderer) {
    why = renderer.error().describe();
    return nullptr;
  }
  auto stage = std::make_unique<Stage>();
  stage->output_ = std::move(*output);
  stage->renderer_ = std::move(*renderer);
  return stage;
}

Played Stage::play(const std::filesystem::path& script, std::int64_t maxFrames, const std::set<std::int64_t>& keepState,
                   const std::set<std::int64_t>& keepImage, kiosk::ScriptPlayerOptions options) {
  Played played;
  auto interpreter = Interpreter::load(script);
  if (!interpreter) {
    ADD_FAILURE() << interpreter.error().describe();
    return played;
  }
  played.messages = interpreter->program().diagnostics;
  ManualClock clock;
  auto loop = runtime::EventLoop::create(clock);
  if (!loop) {
    ADD_FAILURE() << loop.error().describe();
    return played;
  }
  runtime::Show show = startupShow();
  kiosk::FrameLoop frameLoop({60, maxFrames}, clock, &clock, **loop, show, *output_, *renderer_);
  kiosk::ScriptPlayer player(std::move(*interpreter), show, *renderer_, std::move(options));
  player.setReporter([&played](const Diagnostic& d) { played.messages.push_back(d); });
  Keeper keeper(show, player, keepState, keepImage, played.frames);
  frameLoop.addParticipant(player);
  frameLoop.addParticipant(keeper);
  auto stats = frameLoop.run();
  if (!stats) {
    ADD_FAILURE() << stats.error().describe();
    return played;
  }
  played.stats = *stats;
  played.quit = player.interpreter().quit();
  played.finished = player.interpreter().finished();
  played.imagesWritten = player.imagesWritten();
  played.object = player.interpreter().objectSource();
  played.finalShow = show;
  return played;
}

Image Stage::render(const runtime::Show& show) {
  Image image;
  EXPECT_TRUE(output_->beginFrame());
  const render::Size size = output_->size();
  const float aspect = static_cast<float>(size.width) / static_cast<float>(size.height);
  renderer_->draw(show, runtime::computeView(show, aspect), size);
  auto r = output_->readBack(image);
  EXPECT_TRUE(r) << (r ? "" : r.error().describe());
  return image;
}

double coverage(const Image& image) {
  if (image.empty()) return 0;
  std::size_t lit = 0;
  for (std::uint32_t y = 0; y < image.height; ++y) {
    for (std::uint32_t x = 0; x < image.width; ++x) {
      if (image.at(x, y, 0) + image.at(x, y, 1) + image.at(x, y, 2) > 0) ++lit;
    }
  }
  return static_cast<double>(lit) / (static_cast<double>(image.width) * image.height);
}

}  // namespace basalt::script::test
