// Writes the seed corpus of the `lock_message` fuzz target (tests/fuzz/corpus/lock_message) from
// the current wire format, so that a version bump regenerates it instead of hand-made bytes:
//   basalt_lock_message_seeds write tests/fuzz/corpus/lock_message
// and checks a folder against it (ctest `fuzz_seeds.lock_message`: a format change that left
// the seeds behind fails there, naming the file):
//   basalt_lock_message_seeds check tests/fuzz/corpus/lock_message

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "kiosk/lock/lock_protocol.h"

namespace {

using basalt::kiosk::LockBuffer;
using Seed = std::pair<std::string, std::vector<char>>;

template <typename Message>
std::vector<char> bytesOf(const Message& m, std::size_t keep = 0) {
  LockBuffer b{};
  const std::size_t n = basalt::kiosk::encode(m, b);
  const std::size_t size = keep > 0 && keep < n ? keep : n;
  std::vector<char> out(size);
  std::memcpy(out.data(), b.data(), size);
  return out;
}

basalt::kiosk::FrameMessage frame() {
  basalt::kiosk::FrameMessage m;
  m.frame = 42;
  m.showTimeNs = 700'000'000;
  m.sentNs = 123'456;
  m.state.globalRotate = {10, 20, 30};
  m.state.globalFreeRun = true;
  m.state.viewerPosition = {0, 1.7f, 5};
  m.state.viewerRotation = {0, 90, 0};
  auto& p = m.programme;
  p.present = true;
  p.hasItem = true;
  p.mode = 2;
  p.index = 1;
  p.itemStartNs = 5'000'000'000;
  p.mediaStartNs = 16'666'666;
  p.reloads = 1;
  p.setItemName("loop");
  p.moviePassNs = {3'000'333'333, 0, 0, 0};
  m.command.epoch = 1;
  m.command.newest = 3;
  m.command.base = 1;
  m.movies.item = 17;
  m.movies.textures = basalt::kiosk::noMovieFrames();
  m.movies.textures[0] = 29;
  m.session = 0x5EED;
  return m;
}

std::vector<Seed> seeds() {
  using namespace basalt::kiosk;
  std::vector<Seed> s;
  s.emplace_back("frame", bytesOf(frame()));
  FrameMessage withCommand = frame();
  withCommand.command.newest = 4;
  withCommand.command.carried = true;
  withCommand.command.text = "render.prim_type = wireframe";
  s.emplace_back("frame_command", bytesOf(withCommand));
  s.emplace_back("truncated_frame", bytesOf(frame(), 100));
  s.emplace_back("present", bytesOf(PresentMessage{42}));
  ReadyMessage ready;
  ready.frame = 42;
  ready.clockOffsetNs = -1500;
  ready.setNodeName("facet-north");
  s.emplace_back("ready", bytesOf(ready));
  ReadyMessage hello;
  hello.setNodeName("b");
  s.emplace_back("hello", bytesOf(hello));
  s.emplace_back("bye", bytesOf(ByeMessage{999}));
  s.emplace_back("resend", bytesOf(ResendMessage{1, 2}));
  s.emplace_back("command", bytesOf(CommandMessage{1, 2, false, "background 0.2 0.2 0.3"}));
  s.emplace_back("command_gone", bytesOf(CommandMessage{1, 1025, true, "render.prim_type = points"}));
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3 || (std::strcmp(argv[1], "write") != 0 && std::strcmp(argv[1], "check") != 0)) {
    std::fprintf(stderr, "usage: %s write|check FOLDER\n", argv[0]);
    return 2;
  }
  const bool write = std::strcmp(argv[1], "write") == 0;
  const std::filesystem::path folder = argv[2];
  int stale = 0;
  for (const auto& [name, bytes] : seeds()) {
    const std::filesystem::path file = folder / name;
    if (write) {
      std::ofstream(file, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
      continue;
    }
    std::ifstream in(file, std::ios::binary);
    const std::vector<char> have((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (have != bytes) {
      std::fprintf(stderr, "%s: not the current wire format's seed; run: %s write %s\n", file.c_str(), argv[0],
                   folder.c_str());
      ++stale;
    }
  }
  return stale == 0 ? 0 : 1;
}
