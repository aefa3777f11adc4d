#pragma once

/// \file
/// \brief What plays one item of a show (its entry, a playlist item, the attract loop, the
/// standby show): the seam through which scripts, scenes, models and movies plug into the kiosk.
///
/// Built in: "default" (LAVA's start-up cube) and "black". Another kind of item is made by its
/// reader's factory in ItemFactories (the LAVA script interpreter for .mdl, the scene and model
/// loaders for .sce/.obj/.off, the movie player for movies), which the program builds where it
/// starts (app/show_factories.cpp) and passes down to the loader; without one, such an item
/// fails with a message that says so, and the kiosk moves on (DESIGN.md §8: the show goes on).

#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "kiosk/loop/frame_loop.h"
#include "kiosk/manifest/manifest.h"
#include "media/frame_picker.h"
#include "render/output.h"
#include "render/texture_registry.h"
#include "runtime/error.h"
#include "runtime/show/show.h"

namespace basalt::kiosk {

/// \brief Frame-locked followers: how a movie came by the frame it showed in the last frame
/// (kNone: no frame of the leader's was given: a leader, an unlocked show, the leader shows none).
using LeaderFrameResult = media::FrameOutcome;

/// \brief Plays one item into the Show.
///
/// Threading: made on the show loader's thread (files are read there), then used on the frame
/// loop's thread only.
class ItemPlayer {
 public:
  virtual ~ItemPlayer() = default;
  /// \brief The renderer's textures, for items that bring images of their own (a model's maps,
  /// a scene's background, a script's load_texture). Called before each start().
  virtual void useTextures(render::TextureRegistry& textures) { (void)textures; }
  /// \brief Replaces what the show holds with this item, `position` into it (a resumed show).
  /// Must be quick: the frame it is called in must still be on time.
  [[nodiscard]] virtual Result<void> start(runtime::Show& show, Nanos position, double fps) = 0;
  /// \brief Every frame before drawing, while the item plays: a script runs to its next
  /// `draw`; a movie picks its frame. An error ends the item.
  [[nodiscard]] virtual Result<void> beforeDraw(const FrameContext& frame, runtime::Show& show) {
    (void)frame;
    (void)show;
    return {};
  }
  /// \brief After the show is drawn, before the frame is read back or presented: items that
  /// draw over the scene (a movie's full-screen picture). An error ends the item.
  [[nodiscard]] virtual Result<void> afterDraw(const FrameContext& frame, render::Output& output) {
    (void)frame;
    (void)output;
    return {};
  }
  /// \brief True once the item has ended by itself (a script's quit or end, a movie's end).
  [[nodiscard]] virtual bool ended() const { return false; }
  /// \brief How the item is to play this time; the director calls it before each start().
  struct Playback {
    bool loop = false;         ///< play on from the start at the end (gapless) instead of ending
    bool manualClock = false;  ///< the show runs on a ManualClock: wait for decoders, frames are exact
    /// Frame-locked nodes: the show time the item started (its frame 0), on the group's clock. A
    /// movie's frames then fall on that timeline on every node, whenever its decoder starts.
    std::optional<Nanos> timelineStart;
    /// Frame-locked nodes on the system clock: how long a frame may wait for the one due.
    std::chrono::milliseconds patience{0};
  };
  virtual void setPlayback(const Playback& playback) { (void)playback; }
  /// \brief The movie frame on screen (a movie item's number in its clip), or -1: frame-locked
  /// nodes are compared with it.
  [[nodiscard]] virtual std::int64_t shownFrame() const { return -1; }
  /// \brief Frame-locked followers: the movie frame the leader shows in the coming frame (its
  /// shownFrame()), which beforeDraw() shows exactly; -1: none given (the item's own timeline).
  virtual void setLeaderFrame(std::int64_t frame) { (void)frame; }
  /// \brief What the last beforeDraw() did with the leader's frame.
  [[nodiscard]] virtual LeaderFrameResult leaderFrameResult() const { return LeaderFrameResult::kNone; }
};

/// \brief Makes the player of an entry. Called off the frame loop's thread.
using ItemFactory = std::function<Result<std::unique_ptr<ItemPlayer>>(const EntrySpec& entry, const Manifest& show)>;

/// \brief The makers of the items that are not built in, one per kind of entry. One left empty
/// makes such items unplayable, with a message that says so.
struct ItemFactories {
  ItemFactory script;  ///< LAVA scripts (.mdl)
  ItemFactory scene;   ///< scenes (.sce)
  ItemFactory model;   ///< models (.obj, .off)
  ItemFactory movie;   ///< movies, full screen
};

/// \brief The player of `entry` ("default" and "black" are built in, the rest made by
/// `factories`), or why it cannot be played in this build.
[[nodiscard]] Result<std::unique_ptr<ItemPlayer>> prepareItem(const EntrySpec& entry, const Manifest& show,
                                                              const ItemFactories& factories);

/// \brief What a control command runs on.
struct CommandTarget {
  runtime::Show& show;
  render::TextureRegistry* textures = nullptr;  ///< null: load_texture is not available
  std::filesystem::path folder;                 ///< file names are relative to it (the show's folder)
};

/// \brief Runs one LAVA script command on the show (the control server's "run a command").
using CommandRunner = std::function<Result<std::string>(std::string_view command, const CommandTarget& target)>;
/// \brief Runs `command` with `runner`, or says that this build cannot (`runner` is empty).
[[nodiscard]] Result<std::string> runScriptCommand(const CommandRunner& runner, std::string_view command,
                                                   const CommandTarget& target);

}  // namespace basalt::kiosk
