// Frame-locked nodes (kiosk/lock/lock_protocol.h, kiosk/lock/frame_lock.h): the wire format, and a leader
// with followers over ZeroMQ on loopback, each node on its own thread, without rendering.

#include <gtest/gtest.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <arpa/inet.h>
#include <ifaddrs.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zmq.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "kiosk/lock/frame_lock.h"
#include "kiosk/lock/lock_protocol.h"
#include "kiosk/manifest/manifest.h"
#include "kiosk/status/status_board.h"
#include "kiosk/status/status_report.h"
#include "render/output.h"
#include "runtime/event_loop.h"
#include "runtime/show/show.h"

namespace basalt::kiosk {
namespace {

FrameMessage sampleFrame() {
  FrameMessage m;
  m.frame = 1234;
  m.showTimeNs = 20'566'666'666;
  m.sentNs = 987'654'321;
  runtime::Show show;
  show.rotateGlobal({10, 20, 30});
  show.translateLocal({1, 2, 3});
  show.motion().globalFreeRun = true;
  show.motion().framesLeft = 7;
  show.view().perspective = 2.5f;
  show.viewer().position = {4, 1.7f, -3};
  show.viewer().rotation = {0, 45, 0};
  // A tracked head off the display's centre, turned a little (version 4).
  show.head() = {true, {0.3f, -0.2f, 0.55f}, {0.96f, 0, 0.28f}, Nanos{20'550'000'000}};
  m.state = captureLockedState(show);
  m.programme.present = true;
  m.programme.hasItem = true;
  m.programme.mode = 1;
  m.programme.index = 3;
  m.programme.itemStartNs = 12'000'000'000;
  m.programme.mediaStartNs = 250'000'000;
  m.programme.reloads = 2;
  m.programme.setItemName("night sky");
  m.programme.moviePassNs = {3'000'333'333, 0, 0, 0};
  m.command.epoch = 2;
  m.command.newest = 5;
  m.command.base = 3;
  m.command.carried = true;
  m.command.text = "render.prim_type = wireframe";
  m.movies.item = 17;
  m.movies.textures = {29, 0, -1, 1'000'000};
  return m;
}

std::span<const std::byte> bytesOf(const LockBuffer& b, std::size_t n) { return {b.data(), n}; }

// Makes sure every message survives encoding unchanged. Example failure: a field written in one
// order and read in another.
TEST(LockProtocol, MessagesRoundTrip) {
  LockBuffer b{};
  const FrameMessage frame = sampleFrame();
  const std::size_t n = encode(frame, b);
  EXPECT_EQ(n, kFrameMessageBytes);
  auto back = decodeFrame(bytesOf(b, n));
  ASSERT_TRUE(back) << back.error().message();
  EXPECT_EQ(*back, frame);
  EXPECT_EQ(back->programme.itemName(), "night sky");

  runtime::Show follower;
  applyLockedState(back->state, follower);
  EXPECT_EQ(captureLockedState(follower), frame.state);

  ReadyMessage ready;
  ready.frame = -1;
  ready.skipped = 3;
  ready.clockOffsetNs = -42'000;
  ready.setNodeName("facet-north");
  auto r = decodeReady(bytesOf(b, encode(ready, b)));
  ASSERT_TRUE(r) << r.error().message();
  EXPECT_EQ(*r, ready);
  EXPECT_EQ(r->nodeName(), "facet-north");

  auto p = decodePresent(bytesOf(b, encode(PresentMessage{77}, b)));
  ASSERT_TRUE(p);
  EXPECT_EQ(p->frame, 77);
  auto bye = decodeBye(bytesOf(b, encode(ByeMessage{99}, b)));
  ASSERT_TRUE(bye);
  EXPECT_EQ(bye->frame, 99);

  // Version 3: a frame that announces a command without its text, the re-send and the command.
  FrameMessage quiet = sampleFrame();
  quiet.command.carried = false;
  quiet.command.text.clear();
  auto q = decodeFrame(bytesOf(b, encode(quiet, b)));
  ASSERT_TRUE(q) << q.error().message();
  EXPECT_EQ(*q, quiet);
  auto resend = decodeResend(bytesOf(b, encode(ResendMessage{2, 4}, b)));
  ASSERT_TRUE(resend) << resend.error().message();
  EXPECT_EQ(*resend, (ResendMessage{2, 4}));
  CommandMessage command{2, 1030, true, std::string(kCommandTextBytes, 'x')};
  const std::size_t cn = encode(command, b);
  EXPECT_EQ(cn, kCommandMessageBytes);
  auto c = decodeCommand(bytesOf(b, cn));
  ASSERT_TRUE(c) << c.error().message();
  EXPECT_EQ(*c, command);
}

// Makes sure a frame never carries a command text that does not fit its field: it announces the
// number only, and the follower asks for the text. Example failure: a long command cut short
// on the followers.
TEST(LockProtocol, ALongCommandIsAnnouncedWithoutItsText) {
  LockBuffer b{};
  FrameMessage m = sampleFrame();
  m.command.text = std::string(kFrameCommandBytes + 1, 'y');
  auto back = decodeFrame(bytesOf(b, encode(m, b)));
  ASSERT_TRUE(back) << back.error().message();
  EXPECT_FALSE(back->command.carried);
  EXPECT_EQ(back->command.text, "");
  EXPECT_EQ(back->command.newest, 5U);
}

// Makes sure a truncated, lengthened or foreign message is rejected with the reason, never read
// past its end. Example failure: a short packet read as a frame with garbage state.
TEST(LockProtocol, MalformedMessagesAreRejectedWithTheReason) {
  LockBuffer b{};
  const std::size_t n = encode(sampleFrame(), b);
  for (std::size_t len = 0; len < n; ++len) {
    auto d = decodeFrame(bytesOf(b, len));
    ASSERT_FALSE(d) << "accepted " << len << " bytes";
    if (len >= kLockHeaderBytes) {
      EXPECT_NE(d.error().message().find("truncated"), std::string::npos) << len;
    }
  }
  std::array<std::byte, kFrameMessageBytes + 1> longer{};
  std::memcpy(longer.data(), b.data(), n);
  auto tooLong = decodeFrame(longer);
  ASSERT_FALSE(tooLong);
  EXPECT_NE(tooLong.error().message().find(fmt::format("this one has {}", kFrameMessageBytes + 1)), std::string::npos)
      << tooLong.error().message();

  LockBuffer bad = b;
  bad[0] = std::byte{'X'};
  auto magic = decodeFrame(bytesOf(bad, n));
  ASSERT_FALSE(magic);
  EXPECT_NE(magic.error().message().find("magic"), std::string::npos);

  bad = b;
  bad[4] = std::byte{2};  // a basalt from before the commands were sent
  auto version = decodeFrame(bytesOf(bad, n));
  ASSERT_FALSE(version);
  EXPECT_NE(version.error().message().find("version 2, this basalt speaks version 4"), std::string::npos)
      << version.error().message();

  bad = b;
  bad[5] = std::byte{9};
  auto kind = peekKind(bytesOf(bad, n));
  ASSERT_FALSE(kind);
  EXPECT_NE(kind.error().message().find("unknown kind 9"), std::string::npos);

  bad = b;
  bad[6] = std::byte{1};
  EXPECT_FALSE(peekKind(bytesOf(bad, n)));

  // A present where a frame was expected.
  const std::size_t pn = encode(PresentMessage{5}, bad);
  auto wrong = decodeFrame(bytesOf(bad, pn));
  ASSERT_FALSE(wrong);
  EXPECT_NE(wrong.error().message().find("expected a 'frame' message, got 'present'"), std::string::npos);

  // Numbers that are not finite.
  FrameMessage nan = sampleFrame();
  nan.state.perspective = std::numeric_limits<float>::quiet_NaN();
  auto notFinite = decodeFrame(bytesOf(bad, encode(nan, bad)));
  ASSERT_FALSE(notFinite);
  EXPECT_NE(notFinite.error().message().find("not finite"), std::string::npos);

  // A programme with an unknown mode, display or flags, or reserved bytes that are not zero.
  constexpr std::size_t kProgrammeAt = kLockHeaderBytes + 24 + kLockedStateBytes;
  for (const std::size_t at : {kProgrammeAt, kProgrammeAt + 1, kProgrammeAt + 2, kProgrammeAt + 3, kProgrammeAt + 28}) {
    bad = b;
    bad[at] = std::byte{0x7f};
    auto programme = decodeFrame(bytesOf(bad, n));
    ASSERT_FALSE(programme) << "accepted a programme with byte " << at - kProgrammeAt << " = 0x7f";
    EXPECT_NE(programme.error().message().find("programme"), std::string::npos) << programme.error().message();
  }
  bad = b;
  bad[kProgrammeAt + 64 + 7] = std::byte{0x80};  // the first movie pass's sign
  auto pass = decodeFrame(bytesOf(bad, n));
  ASSERT_FALSE(pass);
  EXPECT_NE(pass.error().message().find("negative movie pass"), std::string::npos) << pass.error().message();

  FrameMessage negative = sampleFrame();
  negative.frame = -3;
  EXPECT_FALSE(decodeFrame(bytesOf(bad, encode(negative, bad))));
}

// Makes sure the version-3 command fields are checked: unknown flags, reserved bytes, a text
// longer than its field or not padded with zeros, more than one line, a flag that contradicts
// the length, a base beyond the newest command; and the resend and command messages' own
// fields and sizes. Example failure: a corrupt frame that runs a garbage command on a follower.
TEST(LockProtocol, BadCommandFieldsAreRejectedWithTheReason) {
  LockBuffer b{};
  const std::size_t n = encode(sampleFrame(), b);
  ASSERT_EQ(n, kFrameMessageBytes);
  constexpr std::size_t kCommandAt = kLockHeaderBytes + 24 + kLockedStateBytes + kLockedProgrammeBytes;
  const auto rejects = [&](std::size_t at, std::byte value, std::string_view why) {
    LockBuffer bad = b;
    bad[at] = value;
    auto d = decodeFrame(bytesOf(bad, n));
    ASSERT_FALSE(d) << "accepted byte " << at - kCommandAt << " of the command = " << std::to_integer<int>(value);
    EXPECT_NE(d.error().message().find(why), std::string::npos) << d.error().message();
  };
  rejects(kCommandAt + 14, std::byte{2}, "command flags");                  // an unknown flag
  rejects(kCommandAt + 15, std::byte{1}, "reserved");                       // the reserved byte
  rejects(kCommandAt + 12, std::byte{kFrameCommandBytes + 1}, "too long");  // length beyond the field
  rejects(kCommandAt + 13, std::byte{1}, "too long");                       // length beyond the field (high byte)
  rejects(kCommandAt + 16 + 40, std::byte{'x'}, "padded");                  // text after the length
  rejects(kCommandAt + 16 + 3, std::byte{'\n'}, "one line");                // two lines
  rejects(kCommandAt + 12, std::byte{0}, "flag");                           // carried, but empty
  rejects(kCommandAt + 14, std::byte{0}, "flag");                           // not carried, but a text
  rejects(kCommandAt + 8, std::byte{9}, "base 9 is beyond the newest command 5");

  // The resend and command messages: truncated or lengthened, and their own fields.
  for (std::size_t len = 0; len < kResendMessageBytes; ++len) {
    EXPECT_FALSE(decodeResend(bytesOf(b, encode(ResendMessage{1, 2}, b) - kResendMessageBytes + len))) << len;
  }
  auto fromZero = decodeResend(bytesOf(b, encode(ResendMessage{1, 0}, b)));
  ASSERT_FALSE(fromZero);
  EXPECT_NE(fromZero.error().message().find("from command 0"), std::string::npos);
  const std::size_t cn = encode(CommandMessage{1, 7, false, "background 1 0 0"}, b);
  for (std::size_t len = 0; len < cn; len += 37) EXPECT_FALSE(decodeCommand(bytesOf(b, len))) << len;
  std::array<std::byte, kCommandMessageBytes + 1> longer{};
  std::memcpy(longer.data(), b.data(), cn);
  EXPECT_FALSE(decodeCommand(longer));
  EXPECT_FALSE(decodeCommand(bytesOf(b, encode(CommandMessage{1, 0, false, "x"}, b))));
  EXPECT_FALSE(decodeCommand(bytesOf(b, encode(CommandMessage{1, 3, false, ""}, b))));
  EXPECT_FALSE(decodeCommand(bytesOf(b, encode(CommandMessage{1, 3, false, "a\nb"}, b))));
  LockBuffer bad{};
  const std::size_t bn = encode(CommandMessage{1, 3, false, "x"}, bad);
  bad[kLockHeaderBytes + 10] = std::byte{4};  // an unknown flag
  auto flags = decodeCommand(bytesOf(bad, bn));
  ASSERT_FALSE(flags);
  EXPECT_NE(flags.error().message().find("flags"), std::string::npos);
  // A command where a frame is expected, and the other way round.
  EXPECT_FALSE(decodeFrame(bytesOf(b, cn)));
  EXPECT_FALSE(decodeCommand(bytesOf(b, encode(sampleFrame(), b))));
}

// Makes sure the movie frames a frame announces come through as sent, none (-1) included, and
// that a number below -1 is rejected with the reason; and the leader's session after them.
// Example failure: a corrupt frame makes a follower seek its movie to frame -7.
TEST(LockProtocol, MovieFramesRoundTripAndBadOnesAreRejected) {
  LockBuffer b{};
  FrameMessage none = sampleFrame();
  none.movies = {};
  auto back = decodeFrame(bytesOf(b, encode(none, b)));
  ASSERT_TRUE(back) << back.error().message();
  EXPECT_EQ(back->movies.item, -1);
  EXPECT_EQ(back->movies.textures, noMovieFrames());
  const std::size_t n = encode(sampleFrame(), b);
  back = decodeFrame(bytesOf(b, n));
  ASSERT_TRUE(back) << back.error().message();
  EXPECT_EQ(back->movies, sampleFrame().movies);

  constexpr std::size_t kMoviesAt = kFrameMessageBytes - kLockedHeadBytes - kLockedMovieFramesBytes;
  const auto rejects = [&](FrameMessage m, std::string_view why) {
    LockBuffer bad{};
    auto d = decodeFrame(bytesOf(bad, encode(m, bad)));
    ASSERT_FALSE(d) << "accepted item " << m.movies.item << ", textures " << m.movies.textures.front() << " "
                    << m.movies.textures.back();
    EXPECT_NE(d.error().message().find(why), std::string::npos) << d.error().message();
  };
  FrameMessage m = sampleFrame();
  m.movies.item = -2;
  rejects(m, "movie frame below -1");
  for (std::size_t i = 0; i < kLockedMovieStreams; ++i) {
    m = sampleFrame();
    m.movies.textures[i] = std::numeric_limits<std::int32_t>::min();
    rejects(m, "movie frame below -1");
  }
  // After the movie frames, the leader's session comes through as sent.
  FrameMessage withSession = sampleFrame();
  withSession.session = 0xB45A17U;
  back = decodeFrame(bytesOf(b, encode(withSession, b)));
  ASSERT_TRUE(back) << back.error().message();
  EXPECT_EQ(back->session, 0xB45A17U);
  static_assert(kMoviesAt + 4 + 4 * kLockedMovieStreams + 4 + kLockedHeadBytes == kFrameMessageBytes);
}

// Makes sure the leader's log numbers commands from 1, keeps the newest kKept, and starts again
// with a reload. Example failure: a follower asking for command 3 gets command 4.
TEST(LockProtocol, TheCommandLogKeepsTheNewestAndStartsAgainWithAReload) {
  LockCommandLog log;
  EXPECT_EQ(log.newest(), 0U);
  EXPECT_EQ(log.at(1), nullptr);
  for (std::uint32_t i = 1; i <= LockCommandLog::kKept + 76; ++i) EXPECT_EQ(log.add(fmt::format("c{}", i)), i);
  EXPECT_EQ(log.oldest(), 77U);
  EXPECT_EQ(log.at(76), nullptr);
  ASSERT_NE(log.at(77), nullptr);
  EXPECT_EQ(*log.at(77), "c77");
  EXPECT_EQ(*log.at(LockCommandLog::kKept + 76), fmt::format("c{}", LockCommandLog::kKept + 76));
  EXPECT_EQ(log.at(LockCommandLog::kKept + 77), nullptr);
  log.markShowReset();
  EXPECT_EQ(log.base(), LockCommandLog::kKept + 76);
  log.restart(4);
  EXPECT_EQ(log.epoch(), 4U);
  EXPECT_EQ(log.newest(), 0U);
  EXPECT_EQ(log.base(), 0U);
  EXPECT_EQ(log.oldest(), 1U);
  EXPECT_EQ(log.add("again"), 1U);
  EXPECT_EQ(*log.at(1), "again");
}

// ---- The manifest's [lock] ----

struct ManifestReport {
  std::optional<Manifest> manifest;
  Diagnostics diagnostics;
};

ManifestReport readLockManifest(const std::string& text) {
  ManifestReport report;
  report.manifest =
      readManifestText(text, std::filesystem::temp_directory_path() / "lock-show" / "show.toml", report.diagnostics);
  return report;
}

bool mentions(const ManifestReport& report, int line, std::string_view text) {
  for (const Diagnostic& d : report.diagnostics.items()) {
    if (d.line == line && d.message.find(text) != std::string::npos) return true;
  }
  return false;
}

// Makes sure the [lock] keys reach the spec and mistakes name their line. Example failure: a
// follower without a leader address starts and waits for ever.
TEST(LockManifest, KeysAreReadAndMistakesNamed) {
  auto good = readLockManifest(
      "[lock]\nrole = \"leader\"\nnode = \"a\"\nport = 6000\nfollowers = 2\ntimeout_ms = 8\n"
      "drop_after = 5\nclock = false\n");
  ASSERT_TRUE(good.manifest) << good.diagnostics.format();
  const LockSpec& l = good.manifest->lock;
  EXPECT_EQ(l.role, LockRole::kLeader);
  EXPECT_EQ(l.node, "a");
  EXPECT_EQ(l.port, 6000);
  EXPECT_EQ(l.followers, 2);
  EXPECT_EQ(l.timeoutMs, 8);
  EXPECT_EQ(l.dropAfter, 5);
  EXPECT_FALSE(l.clock);

  auto follower = readLockManifest("[show]\nname = \"x\"\n\n[lock]\nrole = \"follower\"\n");
  EXPECT_FALSE(follower.manifest);
  EXPECT_TRUE(mentions(follower, 4, "a follower needs leader")) << follower.diagnostics.format();

  auto role = readLockManifest("[lock]\nrole = \"boss\"\nleader = \"10.0.0.1\"\n");
  EXPECT_FALSE(role.manifest);
  EXPECT_TRUE(mentions(role, 2, "lock.role"));

  auto typo = readLockManifest("[lock]\nrole = \"follower\"\nleader = \"10.0.0.1\"\ntimeout = 5\n");
  EXPECT_FALSE(typo.manifest);
  EXPECT_TRUE(mentions(typo, 4, "timeout_ms"));

  auto port = readLockManifest("[lock]\nrole = \"leader\"\nport = 70000\n");
  EXPECT_FALSE(port.manifest);
  EXPECT_TRUE(mentions(port, 3, "lock.port"));
}

// ---- Leader and followers on loopback ----

class NullOutput final : public render::Output {
 public:
  [[nodiscard]] std::string_view kind() const override { return "null"; }
  [[nodiscard]] render::Size size() const override { return {4, 4}; }
  [[nodiscard]] std::string describe() const override { return "null"; }
  [[nodiscard]] Result<void> beginFrame() override { return {}; }
  [[nodiscard]] Result<void> present() override { return {}; }
};

int freePortPair() {
  // Ports from the pid keep parallel test processes apart (16 each: the tests use offsets up to
  // 12, each lock three ports), below the kernel's ephemeral range (32768 on) and apart from
  // the locked-kiosk tests' (26000 on) and the lock bench's (29200 on); a clash fails at bind
  // with a message.
  return 10000 + static_cast<int>(::getpid() % 1000) * 16;
}

/// The barrier's wait in the tests where a follower dies: long enough that a live follower starved
/// of the CPU for a while (ctest -j2 beside a build on two cores) is not dropped with it, short
/// enough that the dead one is dropped after three waits within a second.
constexpr int kLoadedBarrierMs = 250;

LockSpec leaderSpec(int port, int followers, int timeoutMs) {
  LockSpec s;
  s.role = LockRole::kLeader;
  s.node = "leader";
  s.listen = "127.0.0.1";
  s.port = port;
  s.followers = followers;
  s.joinTimeoutMs = 10000;
  s.timeoutMs = timeoutMs;
  s.dropAfter = 3;
  return s;
}

LockSpec followerSpec(int port, std::string name, int leaderTimeoutMs = 2000) {
  LockSpec s;
  s.role = LockRole::kFollower;
  s.node = std::move(name);
  s.leader = "127.0.0.1";
  s.port = port;
  s.leaderTimeoutMs = leaderTimeoutMs;
  return s;
}

/// One follower node on its own thread: draws the frames its gate gives until the leader says
/// bye, or `stopAfter` is drawn (a follower killed mid-show).
/// A director as the lock sees it: the leader's moves to item 2 ("b") at a chosen frame, a
/// follower's records the programme it was given and before which frame.
struct FakeDirector final : public LockedDirector {
  LockedProgramme programme;
  std::vector<std::pair<std::int64_t, std::uint32_t>> followed;  // (show time in frames, item index)
  LockCommandLog log;                                            // the leader's commands
  std::vector<std::string> ran;                                  // a follower's: the leader's commands run, in order
  std::uint64_t loads = 1;  // a follower's: its show's loads (a reload: the commands run again)
  int restarts = 0;         // a follower's: times it was told the leader restarted
  void leaderRestarted() override { ++restarts; }
  [[nodiscard]] const LockCommandLog* commandLog() const override { return &log; }
  [[nodiscard]] std::uint64_t showLoads() const override { return loads; }
  Result<std::string> runLeaderCommand(std::string_view command) override {
    ran.emplace_back(command);
    return std::string("done");
  }
  FakeDirector() {
    programme.present = true;
    programme.hasItem = true;
    programme.mode = 2;
    programme.setItemName("a");
  }
  LockedMovieFrames movies;                    // a leader's: the frames its movies show
  std::vector<LockedMovieFrames> moviesGiven;  // a follower's: the leader's, before each frame
  [[nodiscard]] LockedMovieFrames lockedMovieFrames() const override { return movies; }
  void followMovieFrames(const LockedMovieFrames& frames) override { moviesGiven.push_back(frames); }
  [[nodiscard]] LockedMovieCounts movieFrameCounts() const override { return {2, 0}; }
  [[nodiscard]] LockedProgramme lockedProgramme() const override { return programme; }
  bool followProgramme(const LockedProgramme& p, Nanos showTime) override {
    if (p == programme && !followed.empty()) return false;
    programme = p;
    followed.emplace_back(showTime / std::chrono::milliseconds(16), p.index);
    return true;
  }
};

/// Movies no director plays (a script's VCR, --movie streams) as the lock sees them: they use
/// the item slot and the last texture slot; a leader's show frame f's number there, a follower's
/// record the leader's before each frame.
struct FakeMovies final : public LockedMovies {
  std::int64_t frame = -1;               // a leader's: the frame drawn
  std::vector<LockedMovieFrames> given;  // a follower's: the leader's, before each frame
  void lockedMovieFrames(LockedMovieFrames& frames) const override {
    frames.item = frame < 0 ? -1 : static_cast<std::int32_t>(frame % 30);
    frames.textures.back() = frame < 0 ? -1 : static_cast<std::int32_t>((frame + 7) % 30);
  }
  void followMovieFrames(const LockedMovieFrames& frames) override { given.push_back(frames); }
  [[nodiscard]] LockedMovieCounts movieFrameCounts() const override { return {3, 1}; }
};

struct FollowerNode {
  FakeDirector director;
  FakeMovies movies;
  bool withMovies = false;               // the run has movies besides the director's (addMovies)
  std::int64_t reloadAfter = -1;         // the frame after which this node's show is reloaded
  std::vector<std::size_t> commandsRun;  // how many of the leader's commands ran before each frame
  std::vector<std::int64_t> frames;
  std::vector<Mat4> globals;  // the show state drawn with each frame
  FrameLockFigures figures;
  std::string failure;
  std::atomic<bool> quit{false};  // set by the test: stop waiting for frames

  void run(const LockSpec& spec, std::int64_t stopAfter = -1) {
    SystemClock clock;
    auto loop = runtime::EventLoop::create(clock);
    runtime::Show show;
    auto lock = FrameLock::create(spec, clock, show);
    if (!loop || !lock) {
      failure = "cannot create the follower";
      return;
    }
    (*lock)->setDirector(&director);
    if (withMovies) (*lock)->addMovies(movies);
    NullOutput output;
    const auto giveUp = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (std::chrono::steady_clock::now() < giveUp && !quit) {
      auto next = (*lock)->nextFrame(**loop, std::chrono::milliseconds(100));
      if (!next) {
        failure = next.error().message();
        break;
      }
      if (!*next) continue;
      if ((*next)->end) break;
      FrameContext context{(*next)->frame, (*next)->time, false};
      EXPECT_TRUE((*lock)->beforeDraw(context));
      frames.push_back(context.frame);
      globals.push_back(show.position().global);
      commandsRun.push_back(director.ran.size());
      EXPECT_TRUE((*lock)->afterDraw(context, output));
      if (context.frame == reloadAfter) ++director.loads;
      if (stopAfter >= 0 && context.frame >= stopAfter) break;
    }
    figures = (*lock)->figures();
  }
};

struct LeaderNode {
  FakeDirector director;
  FakeMovies movies;
  bool withMovies = false;                       // the run has movies besides the director's (addMovies)
  std::int64_t switchAt = -1;                    // the frame in which the leader's item becomes "b"
  std::map<std::int64_t, std::string> commands;  // script commands its director runs, by frame
  std::int64_t resetAt = -1;                     // the frame in which an item starts a new Show
  std::vector<Mat4> globals;
  FrameLockFigures figures;
  std::int64_t joined = 0;
  std::atomic<std::int64_t> frame{-1};
  std::string failure;

  void run(const LockSpec& spec, std::int64_t frames, std::chrono::microseconds pause) {
    SystemClock clock;
    auto loop = runtime::EventLoop::create(clock);
    runtime::Show show;
    auto lock = FrameLock::create(spec, clock, show);
    if (!loop || !lock) {
      failure = lock ? "no event loop" : lock.error().message();
      return;
    }
    (*lock)->setDirector(&director);
    if (withMovies) (*lock)->addMovies(movies);
    NullOutput output;
    joined = (*lock)->awaitFollowers(**loop);
    for (std::int64_t f = 0; f < frames; ++f) {
      movies.frame = f;
      show.rotateGlobal({1.0f, 0.5f, 0.25f});  // the show moves every frame
      FrameContext context{f, std::chrono::milliseconds(16) * f, f + 1 == frames};
      if (f == switchAt) {  // a control request's `next`, handled by the leader's director
        director.programme.index = 1;
        director.programme.setItemName("b");
        director.programme.itemStartNs = context.time.count();
      }
      if (f == resetAt) director.log.markShowReset();
      if (auto c = commands.find(f); c != commands.end()) director.log.add(c->second);  // a control request's
      EXPECT_TRUE((*lock)->beforeDraw(context));
      globals.push_back(show.position().global);
      EXPECT_TRUE((*lock)->afterDraw(context, output));
      frame = f;
      std::this_thread::sleep_for(pause);
    }
    figures = (*lock)->figures();
  }
};

bool contiguous(const std::vector<std::int64_t>& frames) {
  for (std::size_t i = 1; i < frames.size(); ++i) {
    if (frames[i] != frames[i - 1] + 1) return false;
  }
  return true;
}

// Makes sure two followers draw exactly the leader's frames, every one, with the leader's show
// state, and that the leader waited for both each time. Example failure: a follower that draws
// its own frame count, or state applied one frame late.
TEST(FrameLock, TwoFollowersDrawEveryLeaderFrameWithItsState) {
  const int port = freePortPair();
  constexpr std::int64_t kFrames = 300;
  LeaderNode leader;
  FollowerNode a;
  FollowerNode b;
  std::thread ta([&] { a.run(followerSpec(port, "a")); });
  std::thread tb([&] { b.run(followerSpec(port, "b")); });
  leader.run(leaderSpec(port, 2, 2000), kFrames, std::chrono::microseconds(0));
  ta.join();
  tb.join();
  ASSERT_EQ(leader.failure, "");
  ASSERT_EQ(a.failure, "");
  ASSERT_EQ(b.failure, "");
  EXPECT_EQ(leader.joined, 2);
  for (const FollowerNode* f : {&a, &b}) {
    ASSERT_EQ(f->frames.size(), static_cast<std::size_t>(kFrames));
    EXPECT_EQ(f->frames.front(), 0);
    EXPECT_TRUE(contiguous(f->frames));
    EXPECT_EQ(f->globals, leader.globals);
    EXPECT_EQ(f->figures.skipped, 0);
    EXPECT_EQ(f->figures.presentsMissed, 0);
    EXPECT_EQ(f->figures.malformed, 0);
    EXPECT_EQ(f->figures.maxSkewFrames, 0);
  }
  EXPECT_EQ(a.figures.frameChecksum, b.figures.frameChecksum);
  EXPECT_EQ(leader.figures.barrierTimeouts, 0);
  EXPECT_EQ(leader.figures.followers, 2);
}

// Makes sure a follower that dies leaves the barrier without stopping the others, and is back in
// it when it starts again. Example failure: the leader waits for the dead follower for ever, or
// the restarted one is never waited for again.
TEST(FrameLock, AKilledFollowerLeavesAndRejoinsWithoutStoppingTheOthers) {
  const int port = freePortPair() + 2;
  constexpr std::int64_t kFrames = 400;
  LeaderNode leader;
  FollowerNode a;
  FollowerNode killed;
  FollowerNode restarted;
  std::thread ta([&] { a.run(followerSpec(port, "a")); });
  std::thread tb([&] {
    killed.run(followerSpec(port, "b"), 100);
    while (leader.frame.load() < 150) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    restarted.run(followerSpec(port, "b"));
  });
  leader.run(leaderSpec(port, 2, kLoadedBarrierMs), kFrames, std::chrono::microseconds(2000));
  ta.join();
  tb.join();
  ASSERT_EQ(leader.failure, "");
  ASSERT_EQ(a.frames.size(), static_cast<std::size_t>(kFrames));
  EXPECT_TRUE(contiguous(a.frames));
  ASSERT_FALSE(killed.frames.empty());
  EXPECT_EQ(killed.frames.back(), 100);
  ASSERT_FALSE(restarted.frames.empty());
  EXPECT_GE(restarted.frames.front(), 150);
  EXPECT_EQ(restarted.frames.back(), kFrames - 1);
  EXPECT_TRUE(contiguous(restarted.frames));
  EXPECT_EQ(leader.figures.followersDropped, 1);
  EXPECT_EQ(leader.figures.followersRejoined, 1);
  EXPECT_EQ(leader.figures.followers, 2);
  EXPECT_EQ(leader.figures.followersKnown, 2);
}

// Makes sure a follower whose leader vanishes (no bye) reports it and holds, and notices its
// return, and that a leader back as a new run (restarted) has the follower's director start its
// show again. Example failure: the follower spins drawing nothing without a word, or exits, or
// keeps the old leader's commands on its show.
TEST(FrameLock, ALostLeaderIsReportedAndItsReturnNoticed) {
  const int port = freePortPair() + 4;
  SystemClock clock;
  auto loop = runtime::EventLoop::create(clock);
  auto leaderLoop = runtime::EventLoop::create(clock);  // one loop per thread
  ASSERT_TRUE(loop);
  ASSERT_TRUE(leaderLoop);
  runtime::Show show;
  auto follower = FrameLock::create(followerSpec(port, "a", 100), clock, show);
  ASSERT_TRUE(follower);
  FakeDirector director;
  (*follower)->setDirector(&director);
  NullOutput output;
  std::vector<std::int64_t> drawn;
  auto drawAvailable = [&](std::chrono::milliseconds wait) {
    auto next = (*follower)->nextFrame(**loop, wait);
    ASSERT_TRUE(next);
    if (!*next || (*next)->end) return;
    FrameContext c{(*next)->frame, (*next)->time, false};
    EXPECT_TRUE((*follower)->beforeDraw(c));
    EXPECT_TRUE((*follower)->afterDraw(c, output));
    drawn.push_back(c.frame);
  };
  for (int round = 0; round < 2; ++round) {
    runtime::Show leaderShow;
    LockSpec spec = leaderSpec(port, 1, 500);
    auto leader = FrameLock::create(spec, clock, leaderShow);
    ASSERT_TRUE(leader) << leader.error().message();
    std::thread t([&] {
      for (int i = 0; i < 100 && drawn.size() < 5 * static_cast<std::size_t>(round + 1); ++i) {
        drawAvailable(std::chrono::milliseconds(50));
      }
    });
    EXPECT_EQ((*leader)->awaitFollowers(**leaderLoop), 1);
    for (std::int64_t f = 0; f < 5; ++f) {
      FrameContext c{std::int64_t{100} * round + f, Nanos{0}, false};
      EXPECT_TRUE((*leader)->beforeDraw(c));
      EXPECT_TRUE((*leader)->afterDraw(c, output));
    }
    t.join();
    leader->reset();  // gone without a bye
    // Nothing comes: the follower holds (no frame) and reports the leader lost once.
    for (int i = 0; i < 4; ++i) {
      auto next = (*follower)->nextFrame(**loop, std::chrono::milliseconds(60));
      ASSERT_TRUE(next);
      EXPECT_FALSE(*next);
    }
    const FrameLockFigures f = (*follower)->figures();
    EXPECT_FALSE(f.leaderPresent);
    EXPECT_EQ(f.leaderLost, round + 1);
    // The second leader is a new run (a restart): the follower's director starts its show again.
    EXPECT_EQ(f.leaderRestarts, round);
    EXPECT_EQ(director.restarts, round);
  }
  ASSERT_EQ(drawn.size(), 10U);
  EXPECT_EQ(drawn[5], 100);
}

}  // namespace
}  // namespace basalt::kiosk

namespace basalt::kiosk {
namespace {

// Makes sure a frame-locked node's figures reach /health and /metrics, and that a follower
// without its leader reads as degraded. Example failure: a lost leader the status page calls ok.
TEST(FrameLockStatus, FiguresReachHealthAndMetrics) {
  StatusSnapshot s;
  FrameLockFigures follower;
  follower.node = "north";
  follower.leaderPresent = true;
  follower.skipped = 4;
  follower.clockOffsetUs = -35;
  follower.movieFramesCorrected = 12;
  follower.movieFramesLate = 1;
  s.lock = follower;
  EXPECT_EQ(overallState(s), "ok");
  const auto health = nlohmann::json::parse(healthJson(s));
  EXPECT_EQ(health["lock"]["role"], "follower") << health;
  EXPECT_EQ(health["lock"]["node"], "north") << health;
  EXPECT_EQ(health["lock"]["skipped"], 4) << health;
  const std::string metrics = metricsText(s, ServerCounters{});
  EXPECT_NE(metrics.find("basalt_lock_frames_skipped_total{node=\"north\",role=\"follower\"} 4"), std::string::npos)
      << metrics;
  EXPECT_NE(metrics.find("basalt_lock_clock_offset_seconds{node=\"north\",role=\"follower\"} -3.5e-05"),
            std::string::npos)
      << metrics;
  EXPECT_EQ(health["lock"]["movie_frames_corrected"], 12) << health;
  EXPECT_EQ(health["lock"]["movie_frames_late"], 1) << health;
  EXPECT_NE(metrics.find("basalt_lock_movie_frames_corrected_total{node=\"north\",role=\"follower\"} 12"),
            std::string::npos);
  EXPECT_NE(metrics.find("basalt_lock_movie_frames_late_total{node=\"north\",role=\"follower\"} 1"), std::string::npos);

  s.lock->leaderPresent = false;
  EXPECT_EQ(overallState(s), "degraded");

  FrameLockFigures leader;
  leader.leader = true;
  leader.node = "hub";
  leader.followers = 1;
  leader.followersKnown = 2;
  s.lock = leader;
  EXPECT_EQ(overallState(s), "degraded");  // a follower it knew is out of the barrier
  EXPECT_NE(metricsText(s, ServerCounters{}).find("basalt_lock_followers{node=\"hub\",role=\"leader\"} 1"),
            std::string::npos);
  s.lock.reset();
  EXPECT_FALSE(nlohmann::json::parse(healthJson(s)).contains("lock"));
}

}  // namespace
}  // namespace basalt::kiosk

namespace basalt::kiosk {
namespace {

// Makes sure the leader's programme reaches every follower before the frame in which it changed
// is drawn: an item switched on the leader (a control request's `next`) switches on both
// followers in that same frame, from the same start. Example failure: the programme applied
// after the follower's director ran, one frame late.
TEST(FrameLock, FollowersSwitchItemsInTheLeadersFrame) {
  const int port = freePortPair() + 6;
  constexpr std::int64_t kFrames = 120;
  LeaderNode leader;
  leader.switchAt = 70;
  FollowerNode a;
  FollowerNode b;
  std::thread ta([&] { a.run(followerSpec(port, "a")); });
  std::thread tb([&] { b.run(followerSpec(port, "b")); });
  std::thread tl([&] { leader.run(leaderSpec(port, 2, 2000), kFrames, std::chrono::microseconds(200)); });
  tl.join();
  ta.join();
  tb.join();
  ASSERT_TRUE(leader.failure.empty()) << leader.failure;
  for (const FollowerNode* f : {&a, &b}) {
    ASSERT_EQ(f->frames.size(), static_cast<std::size_t>(kFrames));
    // The first frame brings the leader's programme ("a"), frame 70 the switch to "b".
    ASSERT_EQ(f->director.followed.size(), 2U);
    EXPECT_EQ(f->director.followed[0], (std::pair<std::int64_t, std::uint32_t>{0, 0}));
    EXPECT_EQ(f->director.followed[1], (std::pair<std::int64_t, std::uint32_t>{70, 1}));
    EXPECT_EQ(f->director.programme.itemName(), "b");
    EXPECT_EQ(f->director.programme.itemStartNs, Nanos(std::chrono::milliseconds(16) * 70).count());
    EXPECT_EQ(f->figures.programmeChanges, 1);
  }
  EXPECT_EQ(leader.figures.programmeChanges, 1);
}

// Makes sure movies no director plays (a script's VCR, --movie streams: LockedMovies) are sent
// with every frame in their own slots and handed to a follower's before it draws that frame,
// while the follower's director gets the leader's other slots and -1 in theirs; their corrected
// and late frames add to the director's. Example failure: the follower's movies given the frame
// before (shown one frame late), or its director told to show the script's movie frame as its
// movie item's.
TEST(FrameLock, MoviesBesidesTheDirectorsAreSentInTheirSlots) {
  const int port = freePortPair() + 8;
  constexpr std::int64_t kFrames = 90;
  LeaderNode leader;
  leader.withMovies = true;
  // The director's movie item and its first four streams (the last slot is the movies').
  const auto directors = [](std::int32_t lastSlot) {
    std::array<std::int32_t, kLockedMovieStreams> t = noMovieFrames();
    t[0] = 10, t[1] = 11, t[3] = 13;
    t.back() = lastSlot;
    return t;
  };
  leader.director.movies = {5, directors(-1)};
  FollowerNode a;
  a.withMovies = true;
  std::thread ta([&] { a.run(followerSpec(port, "a")); });
  std::thread tl([&] { leader.run(leaderSpec(port, 1, 2000), kFrames, std::chrono::microseconds(200)); });
  tl.join();
  ta.join();
  ASSERT_TRUE(leader.failure.empty()) << leader.failure;
  ASSERT_TRUE(a.failure.empty()) << a.failure;
  ASSERT_EQ(a.frames.size(), static_cast<std::size_t>(kFrames));
  ASSERT_EQ(a.movies.given.size(), a.frames.size());
  ASSERT_EQ(a.director.moviesGiven.size(), a.frames.size());
  for (std::size_t i = 0; i < a.frames.size(); ++i) {
    const std::int64_t f = a.frames[i];
    // The movies' slots carry what they showed in frame f on the leader, the rest the director's.
    const LockedMovieFrames sent{static_cast<std::int32_t>(f % 30), directors(static_cast<std::int32_t>((f + 7) % 30))};
    EXPECT_EQ(a.movies.given[i], sent) << "frame " << f;
    EXPECT_EQ(a.director.moviesGiven[i], (LockedMovieFrames{-1, directors(-1)})) << "frame " << f;
  }
  EXPECT_EQ(a.figures.movieFramesCorrected, 2 + 3);
  EXPECT_EQ(a.figures.movieFramesLate, 1);
}

}  // namespace
}  // namespace basalt::kiosk

namespace basalt::kiosk {
namespace {

std::vector<std::string> valuesOf(const std::map<std::int64_t, std::string>& m) {
  std::vector<std::string> v;
  for (const auto& [frame, text] : m) v.push_back(text);
  return v;
}

// Makes sure a script command run on the leader runs on both followers before they draw the
// frame in which the leader ran it, and that a command too long for a frame still reaches them,
// in order, by re-send. Example failure: the command applied after the frame was drawn (one
// frame late), or a command after the long one run before it.
TEST(FrameLock, CommandsRunOnEveryFollowerInTheLeadersFrame) {
  const int port = freePortPair() + 10;
  constexpr std::int64_t kFrames = 150;
  LeaderNode leader;
  leader.commands = {{30, "render.prim_type = wireframe"},
                     {60, "background " + std::string(kFrameCommandBytes + 40, '1')},
                     {61, "render.prim_type = points"},
                     {100, "render.prim_type = solid"}};
  FollowerNode a;
  FollowerNode b;
  std::thread ta([&] { a.run(followerSpec(port, "a")); });
  std::thread tb([&] { b.run(followerSpec(port, "b")); });
  std::thread tl([&] { leader.run(leaderSpec(port, 2, 2000), kFrames, std::chrono::microseconds(500)); });
  tl.join();
  ta.join();
  tb.join();
  ASSERT_TRUE(leader.failure.empty()) << leader.failure;
  for (const FollowerNode* f : {&a, &b}) {
    ASSERT_EQ(f->frames.size(), static_cast<std::size_t>(kFrames));
    ASSERT_TRUE(contiguous(f->frames));
    EXPECT_EQ(f->director.ran, valuesOf(leader.commands));
    // Frame 30 is the first drawn with the first command, frame 100 with the fourth.
    EXPECT_EQ(f->commandsRun[29], 0U);
    EXPECT_EQ(f->commandsRun[30], 1U);
    EXPECT_EQ(f->commandsRun[99], 3U);
    EXPECT_EQ(f->commandsRun[100], 4U);
    EXPECT_EQ(f->figures.commandsApplied, 4);
    EXPECT_GE(f->figures.commandsResent, 1);  // the long one came by re-send
    EXPECT_EQ(f->figures.malformed, 0);
  }
  EXPECT_EQ(leader.figures.commandsApplied, 4);
  EXPECT_GE(leader.figures.commandsResent, 2);
}

// Makes sure a follower that missed the leader's commands (it was restarted while they ran)
// gets them again by re-send and runs them in order, skipping those the leader's show no longer
// holds (an item started after them), and that a follower whose own show is reloaded runs them
// again. Example failure: a restarted follower that shows the scene without the commands run
// while it was down, or runs them out of order after the newer one the frame carried.
TEST(FrameLock, AFollowerThatMissedCommandsCatchesUpInOrder) {
  const int port = freePortPair() + 12;
  constexpr std::int64_t kFrames = 400;
  LeaderNode leader;
  leader.commands = {{20, "c1"}, {60, "c2"}, {120, "c3"}, {130, "c4"}, {135, "c5"}, {200, "c6"}, {250, "c7"}};
  leader.resetAt = 110;  // c1 and c2 no longer act after it
  FollowerNode a;
  a.reloadAfter = 300;
  FollowerNode killed;
  FollowerNode restarted;
  std::thread ta([&] { a.run(followerSpec(port, "a")); });
  std::thread tb([&] {
    killed.run(followerSpec(port, "b"), 100);
    while (leader.frame.load() < 150) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    restarted.run(followerSpec(port, "b"));
  });
  leader.run(leaderSpec(port, 2, kLoadedBarrierMs), kFrames, std::chrono::microseconds(2000));
  ta.join();
  tb.join();
  ASSERT_EQ(leader.failure, "");
  const std::vector<std::string> all = valuesOf(leader.commands);
  ASSERT_EQ(killed.director.ran, (std::vector<std::string>{"c1", "c2"}));
  ASSERT_FALSE(restarted.frames.empty());
  EXPECT_GE(restarted.frames.front(), 150);
  // c3..c5 by re-send before its first frame's drawing was over, then c6 and c7 in their frames.
  EXPECT_EQ(restarted.director.ran, (std::vector<std::string>{"c3", "c4", "c5", "c6", "c7"}));
  EXPECT_GE(restarted.figures.commandsResent, 3);
  EXPECT_EQ(restarted.figures.commandsApplied, 5);
  // Follower a ran all seven in their frames, then, its show reloaded after frame 300, the five
  // that still act again.
  std::vector<std::string> aWants = all;
  aWants.insert(aWants.end(), {"c3", "c4", "c5", "c6", "c7"});
  EXPECT_EQ(a.director.ran, aWants);
  ASSERT_EQ(a.frames.size(), static_cast<std::size_t>(kFrames));
  EXPECT_EQ(a.commandsRun[200], 6U);
  EXPECT_EQ(a.commandsRun[250], 7U);
  EXPECT_GE(leader.figures.commandsResent, 8);
  EXPECT_EQ(leader.figures.commandsApplied, 7);
}

}  // namespace
}  // namespace basalt::kiosk

namespace basalt::kiosk {
namespace {

// ---- Authentication and sanity (lock.key_file, max_followers, max_frame_jump) ----

/// A key file readable only by its owner, as `openssl rand -hex 32` writes one.
std::filesystem::path writeKey(std::string_view name, std::string_view key) {
  const auto dir = std::filesystem::temp_directory_path() / fmt::format("basalt-lock-keys-{}", ::getpid());
  std::filesystem::create_directories(dir);
  const auto file = dir / name;
  std::ofstream(file) << key << "\n";
  std::filesystem::permissions(file, std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
  return file;
}

const std::string kGroupKey = "5f0c2a7e91d84b36a1c9e07d2f6b8a4c3e1d5f7092b4c6e8a0d2f4b6c8e0a2d4";
const std::string kOtherKey = "0b1e4d7a2c5f8e1b4d7a0c3f6e9b2d5a8c1f4e7b0d3a6c9f2e5b8d1a4c7f0e3b";

LockSpec keyed(LockSpec spec, const std::filesystem::path& key) {
  spec.keyFile = key;
  return spec;
}

/// Drives a leader's frames (each frame's barrier serves handshakes and answers) from `first`:
/// `limit` of them, or, with no limit, until `done` says so, a frame every 2 ms or so. Returns
/// the frames drawn. Not a timing assertion: the 60 s only end a test that would hang.
template <typename Done>
std::int64_t pumpLeader(FrameLock& leader, runtime::Show& show, Done done, std::int64_t first = 0,
                        std::int64_t limit = -1) {
  NullOutput output;
  const auto giveUp = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  std::int64_t f = first;
  for (; (limit < 0 ? std::chrono::steady_clock::now() < giveUp && !done() : f < first + limit); ++f) {
    show.rotateGlobal({1.0f, 0.0f, 0.0f});
    FrameContext c{f, std::chrono::milliseconds(16) * f, false};
    EXPECT_TRUE(leader.beforeDraw(c));
    EXPECT_TRUE(leader.afterDraw(c, output));
    if (limit < 0) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return f - first;
}

// Makes sure a leader and followers holding the same key lock every frame as without one, and
// say that they are authenticated. Example failure: CURVE set up on one socket only, so that
// the followers never hear a frame.
TEST(FrameLockAuth, NodesWithTheSameKeyLockEveryFrame) {
  const int port = freePortPair();
  const auto key = writeKey("same.key", kGroupKey);
  constexpr std::int64_t kFrames = 120;
  LeaderNode leader;
  FollowerNode a;
  FollowerNode b;
  std::thread ta([&] { a.run(keyed(followerSpec(port, "a"), key)); });
  std::thread tb([&] { b.run(keyed(followerSpec(port, "b"), key)); });
  leader.run(keyed(leaderSpec(port, 2, 2000), key), kFrames, std::chrono::microseconds(0));
  ta.join();
  tb.join();
  ASSERT_EQ(leader.failure, "");
  EXPECT_EQ(leader.joined, 2);
  EXPECT_TRUE(leader.figures.authenticated);
  EXPECT_EQ(leader.figures.rejected.total(), 0);
  for (const FollowerNode* f : {&a, &b}) {
    ASSERT_EQ(f->failure, "");
    ASSERT_EQ(f->frames.size(), static_cast<std::size_t>(kFrames));
    EXPECT_TRUE(contiguous(f->frames));
    EXPECT_EQ(f->globals, leader.globals);
    EXPECT_TRUE(f->figures.authenticated);
    EXPECT_EQ(f->figures.rejected.total(), 0);
  }
  EXPECT_EQ(leader.figures.barrierTimeouts, 0);
}

// Makes sure a follower without the key, and one with another key, are never admitted: the
// leader counts their handshakes and keeps only the follower with the key, and they draw none
// of its frames. Example failure: a leader that accepts any CURVE client (no ZAP check), or
// falls back to no security for a peer that offers none.
TEST(FrameLockAuth, FollowersWithoutTheKeyOrWithAnotherAreNotAdmitted) {
  const int port = freePortPair() + 2;
  const auto key = writeKey("group.key", kGroupKey);
  const auto other = writeKey("other.key", kOtherKey);
  SystemClock clock;
  runtime::Show show;
  auto leader = FrameLock::create(keyed(leaderSpec(port, 1, 20), key), clock, show);
  ASSERT_TRUE(leader) << leader.error().message();
  FollowerNode good;
  FollowerNode none;
  FollowerNode wrong;
  std::thread tn([&] { none.run(followerSpec(port, "none")); });
  std::thread tw([&] { wrong.run(keyed(followerSpec(port, "wrong"), other)); });
  std::thread tg([&] { good.run(keyed(followerSpec(port, "good"), key)); });
  pumpLeader(**leader, show, [&] {
    const FrameLockFigures f = (*leader)->figures();
    return f.rejected.noKey + f.rejected.handshake >= 2 && f.rejected.wrongKey >= 2 && good.frames.size() >= 20;
  });
  const FrameLockFigures f = (*leader)->figures();
  none.quit = true;
  wrong.quit = true;
  (*leader)->sayBye(0);
  tn.join();
  tw.join();
  tg.join();
  // A peer without the key is seen offering none (no_key), or hanging up first when it saw
  // the leader's CURVE greeting (handshake); which one is a race between the two ends.
  EXPECT_GE(f.rejected.noKey + f.rejected.handshake, 2);
  EXPECT_GE(f.rejected.wrongKey, 2);
  EXPECT_GE(none.figures.rejected.noKey + none.figures.rejected.handshake, 1);
  EXPECT_EQ(f.followersKnown, 1);  // "good" only
  EXPECT_EQ(f.followers, 1);
  EXPECT_GE(good.frames.size(), 20U);
  EXPECT_TRUE(none.frames.empty());
  EXPECT_TRUE(wrong.frames.empty());
  EXPECT_FALSE(none.figures.leaderPresent);
  EXPECT_FALSE(wrong.figures.leaderPresent);
}

/// A ZeroMQ socket of the test's own, outside any FrameLock: a forger's.
struct RawZmq {
  void* context = zmq_ctx_new();
  void* socket = nullptr;
  explicit RawZmq(int type) : socket(zmq_socket(context, type)) {
    const int linger = 0;
    zmq_setsockopt(socket, ZMQ_LINGER, &linger, sizeof linger);
  }
  ~RawZmq() {
    zmq_close(socket);
    zmq_ctx_term(context);
  }
  RawZmq(const RawZmq&) = delete;
  RawZmq& operator=(const RawZmq&) = delete;
  RawZmq(RawZmq&&) = delete;
  RawZmq& operator=(RawZmq&&) = delete;
  void send(const LockBuffer& buffer, std::size_t n) const { (void)zmq_send(socket, buffer.data(), n, ZMQ_DONTWAIT); }
};

// Makes sure a well-formed message from a socket without the key changes nothing on a keyed
// leader: the forger's "ready" never makes it a follower, and its handshake is counted.
// Example failure: the leader's answer socket left without CURVE, so that a forged "ready"
// joins the barrier.
TEST(FrameLockAuth, AForgedAnswerChangesNothingOnTheLeader) {
  const int port = freePortPair() + 4;
  const auto key = writeKey("forged.key", kGroupKey);
  SystemClock clock;
  runtime::Show show;
  auto leader = FrameLock::create(keyed(leaderSpec(port, 0, 20), key), clock, show);
  ASSERT_TRUE(leader) << leader.error().message();
  RawZmq forger(ZMQ_DEALER);
  zmq_setsockopt(forger.socket, ZMQ_ROUTING_ID, "intruder", 8);
  ASSERT_EQ(zmq_connect(forger.socket, fmt::format("tcp://127.0.0.1:{}", port + 1).c_str()), 0);
  LockBuffer buffer{};
  ReadyMessage ready;
  ready.setNodeName("intruder");
  std::int64_t sent = 0;
  pumpLeader(**leader, show, [&] {
    ready.frame = sent++ % 2 == 0 ? -1 : 0;  // a hello, then "drew frame 0"
    forger.send(buffer, encode(ready, buffer));
    const LockRejections r = (*leader)->figures().rejected;
    return r.noKey + r.handshake >= 1 && sent >= 20;
  });
  const FrameLockFigures f = (*leader)->figures();
  EXPECT_GE(f.rejected.noKey + f.rejected.handshake, 1);  // no_key, or hung up first (a race)
  EXPECT_EQ(f.followersKnown, 0);
  EXPECT_EQ(f.followers, 0);
  EXPECT_EQ(f.malformed, 0);  // nothing of it reached the decoder
}

// Makes sure a keyed follower takes nothing from a "leader" without the key: well-formed frames
// published by a plain socket at the leader's address are never drawn, and the handshake is
// counted. Example failure: the follower's SUB socket left without CURVE.
TEST(FrameLockAuth, AForgedFrameChangesNothingOnAFollower) {
  const int port = freePortPair() + 6;
  const auto key = writeKey("follower.key", kGroupKey);
  RawZmq fake(ZMQ_PUB);
  ASSERT_EQ(zmq_bind(fake.socket, fmt::format("tcp://127.0.0.1:{}", port).c_str()), 0);
  SystemClock clock;
  auto loop = runtime::EventLoop::create(clock);
  ASSERT_TRUE(loop);
  runtime::Show show;
  auto follower = FrameLock::create(keyed(followerSpec(port, "a"), key), clock, show);
  ASSERT_TRUE(follower) << follower.error().message();
  LockBuffer buffer{};
  FrameMessage frame = sampleFrame();
  std::int64_t drawn = 0;
  const auto refused = [&] {
    const LockRejections r = (*follower)->figures().rejected;
    return r.noKey + r.handshake;  // no_key, or hung up first (a race between the two ends)
  };
  for (int i = 0; i < 2000 && (refused() < 1 || i < 20); ++i) {
    frame.frame = i;
    fake.send(buffer, encode(frame, buffer));
    auto next = (*follower)->nextFrame(**loop, std::chrono::milliseconds(5));
    ASSERT_TRUE(next);
    if (*next && !(*next)->end) ++drawn;
  }
  const FrameLockFigures f = (*follower)->figures();
  EXPECT_GE(refused(), 1);
  EXPECT_EQ(drawn, 0);
  EXPECT_FALSE(f.leaderPresent);
  EXPECT_EQ(f.malformed, 0);
}

/// A TCP relay on loopback that records what the client sent: a wiretap between a follower and
/// its leader.
class Wiretap {
 public:
  Wiretap(int listenPort, int targetPort) : target_(targetPort) {
    listener_ = ::socket(AF_INET, SOCK_STREAM, 0);
    const int on = 1;
    ::setsockopt(listener_, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on);
    sockaddr_in at = loopback(listenPort);
    ok_ = ::bind(listener_, reinterpret_cast<sockaddr*>(&at), sizeof at) == 0 && ::listen(listener_, 4) == 0;
    thread_ = std::thread([this] { relay(); });
  }
  ~Wiretap() {
    stop_ = true;
    thread_.join();
    ::close(listener_);
  }
  Wiretap(const Wiretap&) = delete;
  Wiretap& operator=(const Wiretap&) = delete;
  Wiretap(Wiretap&&) = delete;
  Wiretap& operator=(Wiretap&&) = delete;
  [[nodiscard]] bool ok() const { return ok_; }
  /// What the first client sent, so far.
  [[nodiscard]] std::string captured() {
    const std::lock_guard lock(mutex_);
    return captured_;
  }
  static sockaddr_in loopback(int port) {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(static_cast<std::uint16_t>(port));
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    return a;
  }

 private:
  void relay() {
    int client = -1;
    int server = -1;
    std::array<char, 4096> chunk{};
    while (!stop_) {
      std::vector<pollfd> fds{{listener_, POLLIN, 0}};
      if (client >= 0) fds.push_back({client, POLLIN, 0});
      if (server >= 0) fds.push_back({server, POLLIN, 0});
      if (::poll(fds.data(), fds.size(), 20) <= 0) continue;
      if ((fds[0].revents & POLLIN) != 0) {
        const int s = ::accept(listener_, nullptr, nullptr);
        if (client >= 0) {
          ::close(s);  // one follower connection is enough to capture
        } else {
          client = s;
          server = ::socket(AF_INET, SOCK_STREAM, 0);
          sockaddr_in to = loopback(target_);
          if (::connect(server, reinterpret_cast<sockaddr*>(&to), sizeof to) != 0) stop_ = true;
        }
        continue;
      }
      for (std::size_t i = 1; i < fds.size(); ++i) {
        if ((fds[i].revents & (POLLIN | POLLHUP)) == 0) continue;
        const ssize_t n = ::read(fds[i].fd, chunk.data(), chunk.size());
        if (n <= 0) {
          stop_ = true;
          break;
        }
        const bool fromClient = fds[i].fd == client;
        if (fromClient) {
          const std::lock_guard lock(mutex_);
          captured_.append(chunk.data(), static_cast<std::size_t>(n));
        }
        (void)::write(fromClient ? server : client, chunk.data(), static_cast<std::size_t>(n));
      }
    }
    if (client >= 0) ::close(client);
    if (server >= 0) ::close(server);
  }

  int target_;
  int listener_ = -1;
  bool ok_ = false;
  std::atomic<bool> stop_{false};
  std::mutex mutex_;
  std::string captured_;  // guarded by mutex_
  std::thread thread_;
};

// Makes sure a captured conversation of a follower with its leader, sent again on a new
// connection, admits nobody and is counted: the capture holds a whole CURVE handshake and the
// follower's answers, and proves nothing a second time. Example failure: authentication by a
// fixed token or MAC without a nonce, which a replay passes.
TEST(FrameLockAuth, AReplayedCaptureChangesNothingAndIsCounted) {
  const int port = freePortPair() + 8;
  const int tapped = port + 4;  // the follower's answers go through the wiretap
  const auto key = writeKey("replay.key", kGroupKey);
  SystemClock clock;
  runtime::Show show;
  auto leader = FrameLock::create(keyed(leaderSpec(port, 1, 2000), key), clock, show);
  ASSERT_TRUE(leader) << leader.error().message();
  // The follower's spec names the taps' port pair: its frames and answers pass through them,
  // and the answers' tap keeps what the follower sent.
  Wiretap frames(tapped, port);
  Wiretap answers(tapped + 1, port + 1);
  ASSERT_TRUE(frames.ok());
  ASSERT_TRUE(answers.ok());
  FollowerNode a;
  std::thread ta([&] { a.run(keyed(followerSpec(tapped, "a"), key)); });
  std::int64_t frame = 0;
  frame += pumpLeader(**leader, show, [&] { return a.frames.size() >= 10; });
  const std::string capture = answers.captured();
  ASSERT_GT(capture.size(), 200U);  // the handshake and at least one answer
  const FrameLockFigures before = (*leader)->figures();
  ASSERT_EQ(before.followersKnown, 1);

  // The replay: the captured bytes on a fresh connection to the leader's answer port.
  const int replay = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in to = Wiretap::loopback(port + 1);
  ASSERT_EQ(::connect(replay, reinterpret_cast<sockaddr*>(&to), sizeof to), 0);
  ASSERT_EQ(::write(replay, capture.data(), capture.size()), static_cast<ssize_t>(capture.size()));
  // ZeroMQ reports the replayed handshake's stale cookie as a protocol error (handshake) or a
  // cryptographic one (wrong_key), depending on where it notices.
  const auto refusedHandshakes = [](const FrameLockFigures& f) { return f.rejected.handshake + f.rejected.wrongKey; };
  frame += pumpLeader(
      **leader, show, [&] { return refusedHandshakes((*leader)->figures()) > refusedHandshakes(before); }, frame);
  ::close(replay);
  a.quit = true;
  (*leader)->sayBye(frame);
  ta.join();
  const FrameLockFigures f = (*leader)->figures();
  EXPECT_GT(refusedHandshakes(f), refusedHandshakes(before));
  EXPECT_EQ(f.rejected.noKey, 0);
  EXPECT_EQ(f.followersKnown, 1);  // the replay joined nobody, not even "a" a second time
  EXPECT_LE(f.followers, 1);
  EXPECT_EQ(f.malformed, 0);  // nothing of it reached the decoder
}

// Makes sure a frame number far past the last is refused, not drawn, and counted once per
// frame, with the presents for it; the frames after it, within the bound, are drawn on.
// Example failure: a follower that takes frame 10 000 from a leader at frame 20 and then
// refuses every real frame as old, frozen.
TEST(FrameLockSanity, AFrameJumpPastTheBoundIsRefused) {
  const int port = freePortPair() + 10;
  SystemClock clock;
  runtime::Show show;
  LockSpec leaderAt = leaderSpec(port, 1, 1000);
  leaderAt.dropAfter = 100;  // the follower stays in the barrier through the refused frames
  auto leader = FrameLock::create(leaderAt, clock, show);
  ASSERT_TRUE(leader) << leader.error().message();
  LockSpec spec = followerSpec(port, "a", 20000);
  spec.maxFrameJump = 50;
  FollowerNode a;
  std::thread ta([&] { a.run(spec); });
  auto loop = runtime::EventLoop::create(clock);
  ASSERT_TRUE(loop);
  ASSERT_EQ((*leader)->awaitFollowers(**loop), 1);
  EXPECT_EQ(pumpLeader(**leader, show, [] { return false; }, 0, 20), 20);   // frames 0..19
  EXPECT_EQ(pumpLeader(**leader, show, [] { return false; }, 100, 5), 5);   // 100..104: 81 past 19
  EXPECT_EQ(pumpLeader(**leader, show, [] { return false; }, 20, 20), 20);  // 20..39
  (*leader)->sayBye(39);
  ta.join();
  ASSERT_EQ(a.failure, "");
  std::vector<std::int64_t> expected(40);
  for (std::int64_t i = 0; i < 40; ++i) expected[static_cast<std::size_t>(i)] = i;
  EXPECT_EQ(a.frames, expected);
  EXPECT_EQ(a.figures.rejected.frameJump, 5);
  EXPECT_EQ(a.figures.rejected.outOfSequence, 5);  // "present 100".."present 104"
  EXPECT_EQ(a.figures.leaderLost, 0);
}

// Makes sure a leader admits at most max_followers: the extra follower is refused and counted,
// and the barrier holds only the admitted one. Example failure: a leader whose barrier any
// number of names can fill, so that followers without end stretch every frame.
TEST(FrameLockSanity, FollowersBeyondTheLimitAreRefused) {
  const int port = freePortPair() + 12;
  SystemClock clock;
  runtime::Show show;
  LockSpec spec = leaderSpec(port, 1, 20);
  spec.maxFollowers = 1;
  auto leader = FrameLock::create(spec, clock, show);
  ASSERT_TRUE(leader) << leader.error().message();
  FollowerNode a;
  FollowerNode b;
  std::thread ta([&] { a.run(followerSpec(port, "a")); });
  std::thread tb([&] { b.run(followerSpec(port, "b")); });
  const std::int64_t drawn = pumpLeader(**leader, show, [&] {
    const FrameLockFigures f = (*leader)->figures();
    return f.followersKnown == 1 && f.rejected.followersFull >= 3;
  });
  (*leader)->sayBye(drawn);
  ta.join();
  tb.join();
  const FrameLockFigures f = (*leader)->figures();
  EXPECT_EQ(f.followersKnown, 1);
  EXPECT_EQ(f.followers, 1);
  EXPECT_GE(f.rejected.followersFull, 3);
}

/// An IPv4 address of this machine other than loopback, if it has one.
std::optional<in_addr> outsideAddress() {
  ifaddrs* list = nullptr;
  if (::getifaddrs(&list) != 0) return std::nullopt;
  std::optional<in_addr> found;
  for (const ifaddrs* i = list; i && !found; i = i->ifa_next) {
    if (!i->ifa_addr || i->ifa_addr->sa_family != AF_INET) continue;
    const in_addr a = reinterpret_cast<const sockaddr_in*>(i->ifa_addr)->sin_addr;
    if ((ntohl(a.s_addr) >> 24) != 127) found = a;
  }
  ::freeifaddrs(list);
  return found;
}

// Makes sure a leader listens on loopback unless the manifest names another address: its ports
// answer on 127.0.0.1 and refuse this machine's other addresses. Example failure: the old
// default of 0.0.0.0, which opens the lock to every network the node is on.
TEST(FrameLockSanity, TheDefaultBindIsLoopback) {
  EXPECT_EQ(LockSpec{}.listen, "127.0.0.1");
  auto manifest = readLockManifest("[lock]\nrole = \"leader\"\n");
  ASSERT_TRUE(manifest.manifest) << manifest.diagnostics.format();
  EXPECT_EQ(manifest.manifest->lock.listen, "127.0.0.1");

  const int port = freePortPair() + 14;
  LockSpec spec = manifest.manifest->lock;
  spec.node = "leader";
  spec.port = port;
  SystemClock clock;
  runtime::Show show;
  auto leader = FrameLock::create(spec, clock, show);
  ASSERT_TRUE(leader) << leader.error().message();
  const auto connects = [](in_addr address, int p) {
    const int s = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(static_cast<std::uint16_t>(p));
    to.sin_addr = address;
    const bool ok = ::connect(s, reinterpret_cast<sockaddr*>(&to), sizeof to) == 0;
    ::close(s);
    return ok;
  };
  in_addr loopback{};
  loopback.s_addr = htonl(INADDR_LOOPBACK);
  EXPECT_TRUE(connects(loopback, port));
  EXPECT_TRUE(connects(loopback, port + 1));
  const std::optional<in_addr> outside = outsideAddress();
  if (!outside) GTEST_SKIP() << "this machine has no IPv4 address besides loopback to try";
  EXPECT_FALSE(connects(*outside, port));
  EXPECT_FALSE(connects(*outside, port + 1));
}

// Makes sure the new [lock] keys are read, their mistakes named with their line and the nearest
// key, and a lock off loopback without a key warned about. Example failure: a misspelt key_file
// silently ignored, leaving the lock unauthenticated.
TEST(LockManifest, KeyFileLimitsAndListenAreChecked) {
  const auto key = writeKey("manifest.key", kGroupKey);
  auto good =
      readLockManifest(fmt::format("[lock]\nrole = \"leader\"\nlisten = \"10.0.0.10\"\nkey_file = \"{}\"\n"
                                   "max_followers = 4\nmax_frame_jump = 120\nfollowers = 3\n",
                                   key.string()));
  ASSERT_TRUE(good.manifest) << good.diagnostics.format();
  EXPECT_EQ(good.manifest->lock.keyFile, key);
  EXPECT_EQ(good.manifest->lock.maxFollowers, 4);
  EXPECT_EQ(good.manifest->lock.maxFrameJump, 120);
  EXPECT_EQ(good.manifest->lock.listen, "10.0.0.10");
  EXPECT_FALSE(mentions(good, 3, "unauthenticated")) << good.diagnostics.format();

  auto typo = readLockManifest("[lock]\nrole = \"leader\"\nkey_fil = \"lock.key\"\n");
  EXPECT_FALSE(typo.manifest);
  EXPECT_TRUE(mentions(typo, 3, "key_file")) << typo.diagnostics.format();

  auto open = readLockManifest("[lock]\nrole = \"leader\"\nlisten = \"0.0.0.0\"\n");
  ASSERT_TRUE(open.manifest) << open.diagnostics.format();
  EXPECT_TRUE(mentions(open, 3, "unauthenticated")) << open.diagnostics.format();
  auto remote = readLockManifest("[lock]\nrole = \"follower\"\nleader = \"10.0.0.10\"\n");
  ASSERT_TRUE(remote.manifest);
  EXPECT_TRUE(mentions(remote, 1, "unauthenticated")) << remote.diagnostics.format();
  auto local = readLockManifest("[lock]\nrole = \"follower\"\nleader = \"127.0.0.1\"\n");
  ASSERT_TRUE(local.manifest);
  EXPECT_FALSE(mentions(local, 1, "unauthenticated")) << local.diagnostics.format();

  auto name = readLockManifest("[lock]\nrole = \"leader\"\nlisten = \"eth0\"\n");
  EXPECT_FALSE(name.manifest);
  EXPECT_TRUE(mentions(name, 3, "not an IP address")) << name.diagnostics.format();

  auto tooMany = readLockManifest("[lock]\nrole = \"leader\"\nfollowers = 5\nmax_followers = 2\n");
  EXPECT_FALSE(tooMany.manifest);
  EXPECT_TRUE(mentions(tooMany, 3, "max_followers")) << tooMany.diagnostics.format();

  const auto shortKey = writeKey("short.key", "abc123");
  auto weak = readLockManifest(fmt::format("[lock]\nrole = \"leader\"\nkey_file = \"{}\"\n", shortKey.string()));
  EXPECT_FALSE(weak.manifest);
  EXPECT_TRUE(mentions(weak, 3, "fewer than 32")) << weak.diagnostics.format();

  const auto shared = writeKey("shared.key", kGroupKey);
  std::filesystem::permissions(shared, std::filesystem::perms::others_read, std::filesystem::perm_options::add);
  auto readable = readLockManifest(fmt::format("[lock]\nrole = \"leader\"\nkey_file = \"{}\"\n", shared.string()));
  ASSERT_TRUE(readable.manifest);
  EXPECT_TRUE(mentions(readable, 3, "readable by other users")) << readable.diagnostics.format();
}

// Makes sure the refusals reach /health and /metrics by reason. Example failure: a counter the
// status page never shows, so that an operator cannot see a peer without the key.
TEST(FrameLockStatus, RefusalsReachHealthAndMetrics) {
  StatusSnapshot s;
  FrameLockFigures leader;
  leader.leader = true;
  leader.node = "hub";
  leader.authenticated = true;
  leader.rejected.noKey = 3;
  leader.rejected.wrongKey = 2;
  leader.rejected.followersFull = 1;
  s.lock = leader;
  const auto health = nlohmann::json::parse(healthJson(s));
  EXPECT_EQ(health["lock"]["authenticated"], true) << health;
  EXPECT_EQ(health["lock"]["rejected"]["no_key"], 3) << health;
  EXPECT_EQ(health["lock"]["rejected"]["wrong_key"], 2) << health;
  EXPECT_EQ(health["lock"]["rejected"]["followers_full"], 1) << health;
  EXPECT_EQ(health["lock"]["rejected"]["frame_jump"], 0) << health;
  const std::string metrics = metricsText(s, ServerCounters{});
  EXPECT_NE(metrics.find("basalt_lock_messages_rejected_total{node=\"hub\",role=\"leader\",reason=\"no_key\"} 3"),
            std::string::npos)
      << metrics;
  EXPECT_NE(metrics.find("basalt_lock_messages_rejected_total{node=\"hub\",role=\"leader\",reason=\"wrong_key\"} 2"),
            std::string::npos);
  EXPECT_NE(metrics.find("basalt_lock_authenticated{node=\"hub\",role=\"leader\"} 1"), std::string::npos);
}

}  // namespace
}  // namespace basalt::kiosk
