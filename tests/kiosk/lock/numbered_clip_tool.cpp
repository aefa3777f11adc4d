// basalt_numbered_clip PATH FRAMES FPS: writes a clip whose frame n shows n as bars
// (tests/support/numbered_clip.h), H.264 in the container PATH's extension names, for the
// frame-lock process tests that compare which movie frame each node drew.

#include <cstdio>
#include <cstdlib>
#include <string>

#include "support/numbered_clip.h"

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: basalt_numbered_clip PATH FRAMES FPS\n");
    return 2;
  }
  const int frames = std::atoi(argv[2]);
  const double fps = std::atof(argv[3]);
  auto clip = basalt::test::makeNumberedClip(argv[1], frames, fps, basalt::media::VideoCodec::kH264);
  if (!clip) {
    std::fprintf(stderr, "basalt_numbered_clip: %s\n", clip.error().describe().c_str());
    return 1;
  }
  std::printf("%s\n", clip->string().c_str());
  return 0;
}
