#include "app/show_factories.h"

#include "kiosk/show/movie_item.h"
#include "kiosk/show/readers.h"
#include "kiosk/show/stream_factories.h"

namespace basalt::kiosk {

ShowFactories showFactories() {
  ShowFactories f;
  f.items.script = makeScriptItem;
  f.items.scene = makeSceneItem;
  f.items.model = makeModelItem;
  f.items.movie = makeMovieItem;
  f.movieStreams = makeMovieStream;
  f.cameraStreams = makeCameraStream;
  f.devices = makeDeviceSource;
  f.commands = runControlCommand;
  return f;
}

}  // namespace basalt::kiosk
