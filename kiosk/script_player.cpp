// The kiosk's side of the script language: steps the interpreter in the frame loop and serves
// its files and pictures with media/ and render/.
//
// Limits of this build, each reported to the script's author once, never silently:
// - load_object: the OBJ/OFF loaders are not in this build yet; load_color_cube works.
// - tv.*: no movie player or camera backend yet; the commands are read and answered
//   "not available".
// - save_image writes Sun rasterfiles (ras.im32) once media::writeImage can; until then the
//   picture is written as PNG beside the requested name, and the author is told.

#include "kiosk/script_player.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <fstream>

#include <fmt/format.h>
#include <fmt/std.h>

#include "media/image_io.h"
#include "runtime/formats/model.h"
#include "runtime/log.h"

namespace basalt::kiosk {

BASALT_LOG_CATEGORY(ScriptPlayer, "script");

using script::Feature;
using script::StepStop;

namespace {

std::string lowerExtension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

bool isSunRasterName(const std::filesystem::path& path) {
  const std::string ext = lowerExtension(path);
  return ext == ".im32" || ext == ".im24" || ext == ".im8" || ext == ".ras" || ext == ".rs" || ext == ".sun";
}

}  // namespace

bool isScriptFile(const std::filesystem::path& path) { return lowerExtension(path) == ".mdl"; }

Result<script::Interpreter> loadScript(const std::filesystem::path& path) {
  auto interpreter = script::Interpreter::load(path);
  if (!interpreter) return interpreter;
  for (const script::Diagnostic& d : interpreter->program().diagnostics) printScriptDiagnostic(d);
  return interpreter;
}

bool scriptQuits(const script::Program& program) {
  for (const script::Instr& in : program.instrs) {
    if (program.def(in).action == script::Action::kQuit) return true;
  }
  return false;
}

void printScriptDiagnostic(const script::Diagnostic& diagnostic) {
  std::fflush(stdout);
  fmt::print(stderr, "basalt: {}: {}\n", script::severityName(diagnostic.severity), diagnostic.describe());
  std::fflush(stderr);
}

void printScriptSummary(const ScriptPlayer& player) {
  const script::Interpreter& in = player.interpreter();
  const std::size_t parseErrors = in.program().errorCount();
  const std::uint64_t problems = in.runtimeProblems() + parseErrors;
  std::string state = in.quit() ? "quit" : (in.finished() ? "ended" : "still running when the run stopped");
  fmt::print("basalt: script {}: {} draws, {} commands carried out; {}\n", in.program().file, in.draws(),
             in.instructionsRun(),
             problems == 0 ? std::string("no problems") : fmt::format("{} problems reported above", problems));
  fmt::print("basalt: script {}\n", state);
  const auto& written = player.imagesWritten();
  if (!written.empty()) {
    fmt::print("basalt: save_image wrote {} {} (last: {})\n", written.size(), written.size() == 1 ? "image" : "images",
               written.back().string());
  }
}

Result<void> writeSavedModel(const std::filesystem::path& path, std::string_view text) {
  std::error_code ec;
  const std::filesystem::path folder = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  std::filesystem::create_directories(folder, ec);
  if (ec) return fail(Errc::kIo, fmt::format("cannot create the folder {}: {}", folder, ec.message()), path.string());
  std::filesystem::path partial = folder / fmt::format(".{}.{}.partial", path.filename().string(), ::getpid());
  {
    std::ofstream out(partial, std::ios::binary | std::ios::trunc);
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    out.close();
    if (!out) {
      std::filesystem::remove(partial, ec);
      return fail(Errc::kIo, "cannot write the file; is the disk full or the folder read-only?", path.string());
    }
  }
  std::filesystem::rename(partial, path, ec);
  if (ec) {
    std::filesystem::remove(partial, ec);
    return fail(Errc::kIo, fmt::format("cannot move the file into place: {}", ec.message()), path.string());
  }
  return {};
}

ScriptPlayer::ScriptPlayer(script::Interpreter interpreter, runtime::Show& show, render::Renderer& renderer,
                           ScriptPlayerOptions options)
    : interpreter_(std::move(interpreter)), show_(show), renderer_(renderer), options_(std::move(options)) {}

void ScriptPlayer::setReporter(const script::Interpreter::Reporter& reporter) {
  reporter_ = reporter;
  interpreter_.setReporter(reporter);
}

void ScriptPlayer::warn(std::string message) {
  script::Diagnostic d{script::Severity::kWarning, interpreter_.program().file, interpreter_.currentLine(),
                       std::move(message)};
  if (reporter_) {
    reporter_(d);
  } else {
    log::warn(kLogScriptPlayer, "{}", d.describe());
  }
}

void ScriptPlayer::runStep() {
  step_ = interpreter_.step(show_, *this);
  if (step_.stop == StepStop::kQuit && options_.quitEndsRun) stop_ = true;
}

Result<void> ScriptPlayer::beforeDraw(const FrameContext& frame) {
  (void)frame;
  if (!started_) {
    // Frame 0 shows what the script set up to its first draw.
    started_ = true;
    runStep();
  }
  return {};
}

void ScriptPlayer::adjustView(const FrameContext& frame, runtime::ViewTransforms& view, render::Size size) {
  (void)frame;
  const bool drawn = step_.stop == StepStop::kDraw || step_.stop == StepStop::kBudget;
  if (!drawn || (step_.offset.x == 0 && step_.offset.y == 0) || size.width == 0 || size.height == 0) return;
  // A shift of (x, y) pixels is 2x/width and 2y/height in normalised device coordinates; the
  // translation is applied in clip space, so it scales with w and moves every depth alike.
  const float dx = 2.0f * step_.offset.x / static_cast<float>(size.width);
  const float dy = 2.0f * step_.offset.y / static_cast<float>(size.height);
  view.projection = Mat4::translation({dx, dy, 0}) * view.projection;
}

Result<void> ScriptPlayer::afterDraw(const FrameContext& frame, render::Output& output) {
  (void)frame;
  frameRead_ = false;
  jitterReady_ = false;
  if (interpreter_.finished()) {
    step_ = {};
    return {};
  }
  output_ = &output;
  runStep();
  output_ = nullptr;
  return {};
}

Result<const Image*> ScriptPlayer::currentPicture() {
  if (jitterReady_) return &jitterAverage_;
  if (!output_) {
    return fail(Errc::kUnavailable, "nothing has been drawn yet; put a draw before it");
  }
  if (!frameRead_) {
    if (auto r = output_->readBack(frame_); !r) return std::unexpected(r.error());
    frameRead_ = true;
  }
  return &frame_;
}

Result<void> ScriptPlayer::loadObject(const std::filesystem::path& file, runtime::Show& show) {
  auto model = formats::loadModel(file);
  if (!model) return std::unexpected(model.error());
  for (const formats::Diagnostic& w : model->warnings) warn(w.describe());
  if (auto r = formats::replaceObject(show, *model); !r) return r;
  // The parts name their textures by file (material maps, Extended OBJ colour and reflection
  // maps); each file is read once, and one that cannot be read leaves its parts untextured.
  for (runtime::PartId id = 0; id < show.partCount(); ++id) {
    const runtime::PartState& part = show.part(id);
    for (const std::string* name : {&part.texture, &part.reflectionTexture}) {
      if (name->empty() || renderer_.textures().find(*name) != nullptr) continue;
      auto image = media::readImage(*name);
      auto uploaded = image ? renderer_.textures().setImage(*name, *image) : Result<void>(std::unexpected(image.error()));
      if (!uploaded) warn(fmt::format("the texture of part '{}' is not shown: {}", part.name, uploaded.error().describe()));
    }
  }
  return {};
}

Result<void> ScriptPlayer::loadTexture(const std::filesystem::path& file, const std::string& name) {
  auto image = media::readImage(file);
  if (!image) return std::unexpected(image.error());
  return renderer_.textures().setImage(name, *image);
}

Result<void> ScriptPlayer::saveImage(std::string_view name) {
  auto picture = currentPicture();
  if (!picture) return std::unexpected(picture.error());
  const std::filesystem::path path =
      name.empty() ? options_.outputDir / options_.saveImage : options_.outputDir / std::filesystem::path(name);
  auto written = media::writeImage(path, **picture);
  if (written) {
    written_.push_back(path);
    return {};
  }
  if (!isSunRasterName(path)) return written;
  // The Sun rasterfile writer is not in media/ yet: keep the picture, in PNG, and say so.
  std::filesystem::path png = path;
  png += ".png";
  if (auto r = media::writeImage(png, **picture); !r) return r;
  written_.push_back(png);
  if (!sunRasterWarned_) {
    sunRasterWarned_ = true;
    warn(
        fmt::format("save_image: this build cannot write Sun rasterfiles ({}) yet; the picture went to {} "
                    "as PNG",
                    path.filename().string(), png.string()));
  }
  return {};
}

Result<void> ScriptPlayer::accumulateJitterPass(int pass, int passes) {
  if (!output_) return fail(Errc::kUnavailable, "no pass has been drawn; put a draw inside the jitter loop");
  jitterReady_ = false;
  auto picture = currentPicture();
  if (!picture) return std::unexpected(picture.error());
  const Image& image = **picture;
  if (pass == 0 || jitterSum_.size() != image.pixels.size()) jitterSum_.assign(image.pixels.size(), 0);
  for (std::size_t i = 0; i < image.pixels.size(); ++i) jitterSum_[i] += image.pixels[i];
  if (pass + 1 < passes) return {};
  // The last pass: the average, rounded, is the current picture until the next draw.
  jitterAverage_ = Image::make(image.width, image.height, image.channels, image.type);
  const auto n = static_cast<std::uint32_t>(passes);
  for (std::size_t i = 0; i < jitterSum_.size(); ++i) {
    jitterAverage_.pixels[i] = static_cast<std::uint8_t>((jitterSum_[i] + n / 2) / n);
  }
  jitterReady_ = true;
  return {};
}

Result<void> ScriptPlayer::tv(const script::TvRequest& request) {
  if (request.op == script::TvOp::kCamera) {
    return fail(Errc::kUnavailable,
                "cameras are not available to scripts in this build yet; the show goes on without the camera");
  }
  return fail(Errc::kUnavailable,
              "the movie player is not available to scripts in this build yet; the show goes on without the movie");
}

bool ScriptPlayer::renders(Feature feature) const {
  // What render::Renderer draws today. As the renderer learns a feature, it moves up here, and
  // scripts stop being told that it is not rendered yet.
  switch (feature) {
    case Feature::kRendered:
    case Feature::kRasterOp:
    case Feature::kMarkerShapes:
    case Feature::kAntialiasing:
    case Feature::kColorSelector:
    case Feature::kLineStyle:
    case Feature::kColorInterpolation:
    case Feature::kFillStyle:
    case Feature::kTransparency:
    case Feature::kEdges:
    case Feature::kDepthCue:
    case Feature::kTexture:
    case Feature::kModelClipping:
    case Feature::kStereo:
    case Feature::kFloor:
    case Feature::kShadow: return true;
    case Feature::kNurbs:
    case Feature::kPicking:
    case Feature::kAnnotation:
    case Feature::kSingleBuffering:
    case Feature::kViewMatrix:
    case Feature::kDrawNoClear:
    case Feature::kNoFinalMove:
    case Feature::kJitterDisplay:
    case Feature::kCount: return false;
  }
  return false;
}

}  // namespace basalt::kiosk
