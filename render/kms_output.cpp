// KmsOutput: fullscreen on a display with no desktop running.
//
// Hardware: any DRM/KMS driver with a connected display (a GPU's HDMI or DP port; virtio-gpu in
// the virtual lab). EGL renders into a GBM surface; each presented buffer becomes a KMS
// framebuffer and is scanned out: the first by a modeset, the rest by page flips whose events
// arrive on the DRM fd and pace the frame loop.
// Limits: one connector, one CRTC, its primary plane; XRGB8888. Atomic modesetting is used when
// the driver accepts DRM_CLIENT_CAP_ATOMIC and a test commit succeeds; otherwise the legacy
// SetCrtc/PageFlip calls. Neither path uses native fence fds (IN_FENCE_FD, OUT_FENCE_PTR):
// Mesa's software renderer has no eglDupNativeFenceFDANDROID, and the kernel's implicit fences
// on the buffer already order the scan-out after the rendering.
// Configuration: the manifest's [output] device, connector and mode; BASALT_KMS_LEGACY=1 forces
// the legacy API (ENV_VARS.md).

#include "render/kms_output.h"

#include <drm_fourcc.h>
#include <fcntl.h>
#include <poll.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <vector>

#include <fmt/format.h>

#include "render/drm_handles.h"
#include "render/egl.h"
#include "render/gl.h"
#include "runtime/log.h"
#include "runtime/unique_fd.h"

namespace basalt::render {

BASALT_LOG_CATEGORY(Kms, "render");

namespace {

/// The KMS framebuffer made for a GBM buffer, kept with the buffer (GBM reuses a few buffers,
/// so this is made once per buffer, not per frame).
struct BoFramebuffer {
  int fd = -1;
  std::uint32_t id = 0;
};

void destroyBoFramebuffer(gbm_bo* /*bo*/, void* data) {
  auto* fb = static_cast<BoFramebuffer*>(data);
  if (fb->id) drmModeRmFB(fb->fd, fb->id);
  delete fb;  // owned by the buffer's user data; this is its deleter
}

KmsMode toKmsMode(const drmModeModeInfo& m) {
  KmsMode mode;
  mode.width = m.hdisplay;
  mode.height = m.vdisplay;
  mode.preferred = (m.type & DRM_MODE_TYPE_PREFERRED) != 0;
  mode.interlaced = (m.flags & DRM_MODE_FLAG_INTERLACE) != 0;
  if (m.htotal > 0 && m.vtotal > 0) {
    mode.refresh = static_cast<double>(m.clock) * 1000.0 / (static_cast<double>(m.htotal) * m.vtotal);
    if (mode.interlaced) mode.refresh *= 2;
    if (m.flags & DRM_MODE_FLAG_DBLSCAN) mode.refresh /= 2;
  } else {
    mode.refresh = m.vrefresh;
  }
  return mode;
}

std::string connectorName(const drmModeConnector& c) {
  const char* type = drmModeGetConnectorTypeName(c.connector_type);
  return fmt::format("{}-{}", type ? type : "Unknown", c.connector_type_id);
}

/// The id of property `name` of a KMS object, or 0.
std::uint32_t propertyId(int fd, std::uint32_t object, std::uint32_t type, std::string_view name,
                         std::uint64_t* value = nullptr) {
  drm::ObjectProperties props(drmModeObjectGetProperties(fd, object, type));
  if (!props) return 0;
  for (std::uint32_t i = 0; i < props->count_props; ++i) {
    drm::Property p(drmModeGetProperty(fd, props->props[i]));
    if (p && name == p->name) {
      if (value) *value = props->prop_values[i];
      return p->prop_id;
    }
  }
  return 0;
}

std::string errnoText(int e) { return std::strerror(e); }

}  // namespace

struct KmsOutput::State {
  UniqueFd fd;
  std::string devicePath;
  drm::GbmDevice gbm;
  drm::GbmSurface surface;
  std::unique_ptr<EglContext> context;
  EglSurface eglSurface;  // on `surface`
  std::string renderer;

  std::uint32_t connectorId = 0;
  std::uint32_t crtcId = 0;
  std::uint32_t planeId = 0;
  drmModeModeInfo modeInfo{};
  KmsMode mode;
  std::string connector;
  drm::Crtc savedCrtc;  // restored on close, so a console comes back

  bool atomic = false;
  drm::AtomicRequest request;  // reused for every commit: no allocation per frame
  std::uint32_t modeBlob = 0;
  struct {
    std::uint32_t connectorCrtc = 0, crtcMode = 0, crtcActive = 0;
    std::uint32_t fb = 0, crtc = 0, srcX = 0, srcY = 0, srcW = 0, srcH = 0, crtcX = 0, crtcY = 0, crtcW = 0, crtcH = 0;
  } prop;
  std::uint32_t dpmsProperty = 0;  // legacy

  gbm_bo* onScreen = nullptr;
  gbm_bo* pending = nullptr;
  bool modesetDone = false;
  bool displayOn = true;
  std::uint64_t flips = 0;
  drmEventContext events{};

  ~State() {
    if (pending && fd) {
      // Let the last flip land before its buffers go.
      pollfd p{fd.get(), POLLIN, 0};
      if (::poll(&p, 1, 200) > 0) drmHandleEvent(fd.get(), &events);
    }
    if (savedCrtc && savedCrtc->mode_valid && fd) {
      drmModeSetCrtc(fd.get(), savedCrtc->crtc_id, savedCrtc->buffer_id, savedCrtc->x, savedCrtc->y, &connectorId, 1,
                     &savedCrtc->mode);
    }
    if (surface) {
      if (pending) gbm_surface_release_buffer(surface.get(), pending);
      if (onScreen) gbm_surface_release_buffer(surface.get(), onScreen);
    }
    eglSurface.reset();  // before the GBM surface under it
    context.reset();     // and with it the EGL display, before the GBM device it was made on
    surface.reset();
    gbm.reset();
    if (modeBlob && fd) drmModeDestroyPropertyBlob(fd.get(), modeBlob);
    if (fd) drmDropMaster(fd.get());
  }

  static void onFlip(int /*fd*/, unsigned /*frame*/, unsigned /*sec*/, unsigned /*usec*/, void* data) {
    auto* self = static_cast<State*>(data);
    if (self->onScreen && self->surface) gbm_surface_release_buffer(self->surface.get(), self->onScreen);
    self->onScreen = self->pending;
    self->pending = nullptr;
    ++self->flips;
  }

  Result<std::uint32_t> framebufferFor(gbm_bo* bo) {
    if (auto* fb = static_cast<BoFramebuffer*>(gbm_bo_get_user_data(bo))) return fb->id;
    const std::uint32_t width = gbm_bo_get_width(bo);
    const std::uint32_t height = gbm_bo_get_height(bo);
    std::uint32_t handles[4] = {};
    std::uint32_t strides[4] = {};
    std::uint32_t offsets[4] = {};
    const int planes = gbm_bo_get_plane_count(bo);
    for (int i = 0; i < planes && i < 4; ++i) {
      handles[i] = gbm_bo_get_handle_for_plane(bo, i).u32;
      strides[i] = gbm_bo_get_stride_for_plane(bo, i);
      offsets[i] = gbm_bo_get_offset(bo, i);
    }
    std::uint32_t id = 0;
    int rc = drmModeAddFB2(fd.get(), width, height, gbm_bo_get_format(bo), handles, strides, offsets, &id, 0);
    if (rc != 0) {
      // Older drivers: the depth/bpp call.
      rc = drmModeAddFB(fd.get(), width, height, 24, 32, gbm_bo_get_stride(bo), gbm_bo_get_handle(bo).u32, &id);
    }
    if (rc != 0) {
      return fail(Errc::kIo, fmt::format("cannot make a KMS framebuffer from a GBM buffer on {}: {}", devicePath,
                                         errnoText(errno)));
    }
    auto* fb = new BoFramebuffer{fd.get(), id};  // owned by the buffer from here on
    gbm_bo_set_user_data(bo, fb, destroyBoFramebuffer);
    return id;
  }

  void addPlane(std::uint32_t fbId) {
    drmModeAtomicReq* r = request.get();
    drmModeAtomicAddProperty(r, planeId, prop.fb, fbId);
    drmModeAtomicAddProperty(r, planeId, prop.crtc, crtcId);
    drmModeAtomicAddProperty(r, planeId, prop.srcX, 0);
    drmModeAtomicAddProperty(r, planeId, prop.srcY, 0);
    drmModeAtomicAddProperty(r, planeId, prop.srcW, std::uint64_t{mode.width} << 16);
    drmModeAtomicAddProperty(r, planeId, prop.srcH, std::uint64_t{mode.height} << 16);
    drmModeAtomicAddProperty(r, planeId, prop.crtcX, 0);
    drmModeAtomicAddProperty(r, planeId, prop.crtcY, 0);
    drmModeAtomicAddProperty(r, planeId, prop.crtcW, mode.width);
    drmModeAtomicAddProperty(r, planeId, prop.crtcH, mode.height);
  }

  int atomicModeset(std::uint32_t fbId, bool active, std::uint32_t flags) {
    drmModeAtomicSetCursor(request.get(), 0);
    drmModeAtomicAddProperty(request.get(), connectorId, prop.connectorCrtc, crtcId);
    drmModeAtomicAddProperty(request.get(), crtcId, prop.crtcMode, modeBlob);
    drmModeAtomicAddProperty(request.get(), crtcId, prop.crtcActive, active ? 1 : 0);
    addPlane(fbId);
    return drmModeAtomicCommit(fd.get(), request.get(), DRM_MODE_ATOMIC_ALLOW_MODESET | flags, this);
  }

  Result<void> modeset(std::uint32_t fbId) {
    if (atomic) {
      if (atomicModeset(fbId, true, DRM_MODE_ATOMIC_TEST_ONLY) == 0 && atomicModeset(fbId, true, 0) == 0) return {};
      log::warn(kLogKms, "atomic modeset on {} failed ({}); using legacy modesetting", devicePath, errnoText(errno));
      atomic = false;
    }
    if (drmModeSetCrtc(fd.get(), crtcId, fbId, 0, 0, &connectorId, 1, &modeInfo) != 0) {
      return fail(Errc::kIo, fmt::format("cannot set mode {} on {} of {}: {}", describeMode(mode), connector,
                                         devicePath, errnoText(errno)));
    }
    return {};
  }

  Result<void> flip(std::uint32_t fbId) {
    int rc = 0;
    if (atomic) {
      drmModeAtomicSetCursor(request.get(), 0);
      addPlane(fbId);
      rc = drmModeAtomicCommit(fd.get(), request.get(), DRM_MODE_ATOMIC_NONBLOCK | DRM_MODE_PAGE_FLIP_EVENT, this);
    } else {
      rc = drmModePageFlip(fd.get(), crtcId, fbId, DRM_MODE_PAGE_FLIP_EVENT, this);
    }
    if (rc != 0) {
      return fail(Errc::kIo, fmt::format("page flip on {} of {} failed: {}", connector, devicePath, errnoText(errno)));
    }
    return {};
  }
};

namespace {

/// Opens a card and checks that this process is DRM master with something connected.
Result<UniqueFd> openCard(const std::string& path) {
  UniqueFd fd(::open(path.c_str(), O_RDWR | O_CLOEXEC));
  if (!fd) {
    const int e = errno;
    if (e == EACCES) {
      return fail(Errc::kPermissionDenied,
                  fmt::format("cannot open {}: permission denied; run as a member of the 'video' group (the "
                              "systemd unit in configs/ does)",
                              path));
    }
    return fail(e == ENOENT ? Errc::kNotFound : Errc::kIo, fmt::format("cannot open {}: {}", path, errnoText(e)));
  }
  if (!drmIsMaster(fd.get()) && drmSetMaster(fd.get()) != 0) {
    return fail(Errc::kUnavailable,
                fmt::format("another program (a desktop or display server) holds {}; stop it, or use the window "
                            "output",
                            path));
  }
  return fd;
}

std::vector<KmsConnector> listConnectors(int fd, const drmModeRes& res, std::vector<drm::Connector>& raw) {
  std::vector<KmsConnector> out;
  for (int i = 0; i < res.count_connectors; ++i) {
    drm::Connector c(drmModeGetConnector(fd, res.connectors[i]));
    if (!c) continue;
    KmsConnector k;
    k.id = c->connector_id;
    k.name = connectorName(*c);
    k.connected = c->connection == DRM_MODE_CONNECTED;
    for (int m = 0; m < c->count_modes; ++m) k.modes.push_back(toKmsMode(c->modes[m]));
    out.push_back(std::move(k));
    raw.push_back(std::move(c));
  }
  return out;
}

/// A CRTC that can drive the connector: the one it is on, else the first its encoders allow.
std::optional<std::pair<std::uint32_t, int>> findCrtc(int fd, const drmModeRes& res, const drmModeConnector& c) {
  const auto indexOf = [&](std::uint32_t crtc) -> int {
    for (int i = 0; i < res.count_crtcs; ++i) {
      if (res.crtcs[i] == crtc) return i;
    }
    return -1;
  };
  if (c.encoder_id) {
    drm::Encoder e(drmModeGetEncoder(fd, c.encoder_id));
    if (e && e->crtc_id && indexOf(e->crtc_id) >= 0) return std::pair{e->crtc_id, indexOf(e->crtc_id)};
  }
  for (int i = 0; i < c.count_encoders; ++i) {
    drm::Encoder e(drmModeGetEncoder(fd, c.encoders[i]));
    if (!e) continue;
    for (int k = 0; k < res.count_crtcs; ++k) {
      if (e->possible_crtcs & (1u << k)) return std::pair{res.crtcs[k], k};
    }
  }
  return std::nullopt;
}

/// The primary plane that can show `crtcIndex`.
std::uint32_t findPrimaryPlane(int fd, int crtcIndex) {
  drm::PlaneResources planes(drmModeGetPlaneResources(fd));
  if (!planes) return 0;
  for (std::uint32_t i = 0; i < planes->count_planes; ++i) {
    drm::Plane p(drmModeGetPlane(fd, planes->planes[i]));
    if (!p || !(p->possible_crtcs & (1u << crtcIndex))) continue;
    std::uint64_t type = 0;
    if (propertyId(fd, p->plane_id, DRM_MODE_OBJECT_PLANE, "type", &type) && type == DRM_PLANE_TYPE_PRIMARY) {
      return p->plane_id;
    }
  }
  return 0;
}

Result<EGLConfig> chooseConfig(EGLDisplay display) {
  for (const EGLint depth : {24, 16}) {
    const EGLint attributes[] = {EGL_SURFACE_TYPE,
                                 EGL_WINDOW_BIT,
                                 EGL_RED_SIZE,
                                 8,
                                 EGL_GREEN_SIZE,
                                 8,
                                 EGL_BLUE_SIZE,
                                 8,
                                 EGL_ALPHA_SIZE,
                                 0,
                                 EGL_DEPTH_SIZE,
                                 depth,
                                 EGL_RENDERABLE_TYPE,
                                 EGL_OPENGL_ES3_BIT,
                                 EGL_NONE};
    EGLint count = 0;
    if (!eglChooseConfig(display, attributes, nullptr, 0, &count) || count == 0) continue;
    std::vector<EGLConfig> configs(static_cast<std::size_t>(count));
    eglChooseConfig(display, attributes, configs.data(), count, &count);
    for (EGLConfig c : configs) {
      EGLint visual = 0;
      if (eglGetConfigAttrib(display, c, EGL_NATIVE_VISUAL_ID, &visual) &&
          static_cast<std::uint32_t>(visual) == GBM_FORMAT_XRGB8888) {
        return c;
      }
    }
  }
  return fail(Errc::kUnavailable, "EGL offers no XRGB8888 window configuration with a depth buffer on GBM");
}

}  // namespace

KmsOutput::KmsOutput(std::unique_ptr<State> state) : state_(std::move(state)) {}
KmsOutput::~KmsOutput() = default;

Result<std::unique_ptr<KmsOutput>> KmsOutput::open(const OutputRequest& request) {
  auto state = std::make_unique<State>();
  State& s = *state;
  // The card: the one asked for, or the first with a connected display.
  std::vector<std::string> candidates;
  if (!request.drmDevice.empty()) {
    candidates.push_back(request.drmDevice);
  } else {
    for (int i = 0; i < 16; ++i) {
      const std::string path = fmt::format("/dev/dri/card{}", i);
      if (::access(path.c_str(), F_OK) == 0) candidates.push_back(path);
    }
    if (candidates.empty()) {
      return fail(Errc::kNotFound, "there is no DRM device (/dev/dri/card*); this machine has no display driver");
    }
  }
  drm::Resources res;
  std::vector<KmsConnector> connectors;
  std::vector<drm::Connector> rawConnectors;
  std::optional<Error> lastError;
  KmsSelection selection;
  for (const std::string& path : candidates) {
    auto fd = openCard(path);
    if (!fd) {
      lastError = fd.error();
      continue;
    }
    drm::Resources r(drmModeGetResources(fd->get()));
    if (!r) {
      lastError = Error(Errc::kUnsupported, fmt::format("{} cannot do modesetting (no KMS resources)", path));
      continue;
    }
    std::vector<drm::Connector> raw;
    auto list = listConnectors(fd->get(), *r, raw);
    std::optional<ModeWish> wish = request.mode;
    auto chosen = selectConnectorAndMode(list, request.connector, wish);
    if (!chosen) {
      lastError = chosen.error().withContext(path);
      continue;
    }
    s.fd = std::move(*fd);
    s.devicePath = path;
    res = std::move(r);
    connectors = std::move(list);
    rawConnectors = std::move(raw);
    selection = *chosen;
    break;
  }
  if (!s.fd) return std::unexpected(*lastError);

  const drmModeConnector& conn = *rawConnectors[selection.connector];
  s.connectorId = conn.connector_id;
  s.connector = connectors[selection.connector].name;
  s.modeInfo = conn.modes[selection.mode];
  s.mode = connectors[selection.connector].modes[selection.mode];
  auto crtc = findCrtc(s.fd.get(), *res, conn);
  if (!crtc) return fail(Errc::kUnavailable, fmt::format("no CRTC of {} can drive {}", s.devicePath, s.connector));
  s.crtcId = crtc->first;
  s.savedCrtc.reset(drmModeGetCrtc(s.fd.get(), s.crtcId));
  s.dpmsProperty = propertyId(s.fd.get(), s.connectorId, DRM_MODE_OBJECT_CONNECTOR, "DPMS");

  // Atomic when the driver offers it (and nobody asked for legacy).
  const char* legacyEnv = std::getenv("BASALT_KMS_LEGACY");
  const bool wantAtomic = !(legacyEnv && std::string_view(legacyEnv) == "1");
  if (wantAtomic && drmSetClientCap(s.fd.get(), DRM_CLIENT_CAP_UNIVERSAL_PLANES, 1) == 0 &&
      drmSetClientCap(s.fd.get(), DRM_CLIENT_CAP_ATOMIC, 1) == 0) {
    s.planeId = findPrimaryPlane(s.fd.get(), crtc->second);
    const int fd = s.fd.get();
    s.prop.connectorCrtc = propertyId(fd, s.connectorId, DRM_MODE_OBJECT_CONNECTOR, "CRTC_ID");
    s.prop.crtcMode = propertyId(fd, s.crtcId, DRM_MODE_OBJECT_CRTC, "MODE_ID");
    s.prop.crtcActive = propertyId(fd, s.crtcId, DRM_MODE_OBJECT_CRTC, "ACTIVE");
    const auto plane = [&](std::string_view name) { return propertyId(fd, s.planeId, DRM_MODE_OBJECT_PLANE, name); };
    s.prop.fb = plane("FB_ID");
    s.prop.crtc = plane("CRTC_ID");
    s.prop.srcX = plane("SRC_X");
    s.prop.srcY = plane("SRC_Y");
    s.prop.srcW = plane("SRC_W");
    s.prop.srcH = plane("SRC_H");
    s.prop.crtcX = plane("CRTC_X");
    s.prop.crtcY = plane("CRTC_Y");
    s.prop.crtcW = plane("CRTC_W");
    s.prop.crtcH = plane("CRTC_H");
    const bool complete = s.planeId && s.prop.connectorCrtc && s.prop.crtcMode && s.prop.crtcActive && s.prop.fb &&
                          s.prop.crtc && s.prop.srcW && s.prop.srcH && s.prop.crtcW && s.prop.crtcH;
    if (complete && drmModeCreatePropertyBlob(fd, &s.modeInfo, sizeof s.modeInfo, &s.modeBlob) == 0) {
      s.request.reset(drmModeAtomicAlloc());
      s.atomic = s.request != nullptr;
    }
    if (!s.atomic) log::info(kLogKms, "{}: atomic modesetting incomplete; using legacy page flips", s.devicePath);
  }

  s.gbm.reset(gbm_create_device(s.fd.get()));
  if (!s.gbm)
    return fail(Errc::kUnavailable, fmt::format("GBM cannot use {}; is Mesa's libgbm1 installed?", s.devicePath));
  s.surface.reset(gbm_surface_create(s.gbm.get(), s.mode.width, s.mode.height, GBM_FORMAT_XRGB8888,
                                     GBM_BO_USE_SCANOUT | GBM_BO_USE_RENDERING));
  if (!s.surface) {
    return fail(Errc::kUnavailable, fmt::format("GBM cannot make a {}x{} scan-out surface on {}", s.mode.width,
                                                s.mode.height, s.devicePath));
  }
  auto display = EglDisplay::openPlatform(EGL_PLATFORM_GBM_KHR, s.gbm.get(), "GBM on " + s.devicePath);
  if (!display) return std::unexpected(display.error());
  auto config = chooseConfig((*display)->handle());
  if (!config) return std::unexpected(config.error());
  auto context = EglContext::create(*display, *config);
  if (!context) return std::unexpected(context.error());
  s.context = std::move(*context);
  auto eglSurface = EglSurface::createWindow(*display, *config, s.surface.get(), "GBM on " + s.devicePath);
  if (!eglSurface) return std::unexpected(eglSurface.error());
  s.eglSurface = std::move(*eglSurface);
  if (auto r = s.context->makeCurrent(s.eglSurface.handle()); !r) return std::unexpected(r.error());
  s.renderer = gl::rendererDescription();
  s.events.version = 2;
  s.events.page_flip_handler = &State::onFlip;
  log::info(kLogKms, "{}: {} at {} ({} modesetting)", s.devicePath, s.connector, describeMode(s.mode),
            s.atomic ? "atomic" : "legacy");
  return std::unique_ptr<KmsOutput>(new KmsOutput(std::move(state)));
}

Size KmsOutput::size() const { return {state_->mode.width, state_->mode.height}; }

std::string KmsOutput::describe() const {
  return fmt::format("kms {} on {} of {} ({} modesetting, {})", describeMode(state_->mode), state_->connector,
                     state_->devicePath, state_->atomic ? "atomic" : "legacy", state_->renderer);
}

bool KmsOutput::atomic() const { return state_->atomic; }
const std::string& KmsOutput::connectorName() const { return state_->connector; }
const KmsMode& KmsOutput::mode() const { return state_->mode; }
std::uint64_t KmsOutput::flipsCompleted() const { return state_->flips; }
int KmsOutput::paceFd() const { return state_->fd.get(); }
bool KmsOutput::readyForFrame() const { return state_->pending == nullptr; }

void KmsOutput::onPaceReady() { drmHandleEvent(state_->fd.get(), &state_->events); }

Result<void> KmsOutput::waitForFlip(int timeoutMs) {
  while (state_->pending) {
    pollfd p{state_->fd.get(), POLLIN, 0};
    const int n = ::poll(&p, 1, timeoutMs);
    if (n <= 0) {
      return fail(Errc::kTimeout,
                  fmt::format("the page flip on {} did not complete within {} ms", state_->connector, timeoutMs));
    }
    onPaceReady();
  }
  return {};
}

Result<void> KmsOutput::beginFrame() {
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glViewport(0, 0, static_cast<GLsizei>(state_->mode.width), static_cast<GLsizei>(state_->mode.height));
  return {};
}

Result<void> KmsOutput::present() {
  State& s = *state_;
  if (!s.displayOn) return {};  // nothing to show: the frame is dropped
  if (s.pending) {
    if (auto r = waitForFlip(1000); !r) return r;
  }
  if (!eglSwapBuffers(s.context->display()->handle(), s.eglSurface.handle())) {
    return fail(Errc::kIo, fmt::format("eglSwapBuffers failed ({})", eglErrorName(eglGetError())));
  }
  gbm_bo* bo = gbm_surface_lock_front_buffer(s.surface.get());
  if (!bo) return fail(Errc::kResourceExhausted, "GBM has no free buffer to show");
  auto fb = s.framebufferFor(bo);
  if (!fb) {
    gbm_surface_release_buffer(s.surface.get(), bo);
    return std::unexpected(fb.error());
  }
  if (!s.modesetDone) {
    if (auto r = s.modeset(*fb); !r) {
      gbm_surface_release_buffer(s.surface.get(), bo);
      return r;
    }
    s.modesetDone = true;
    s.onScreen = bo;
    return {};
  }
  s.pending = bo;
  if (auto r = s.flip(*fb); !r) {
    s.pending = nullptr;
    gbm_surface_release_buffer(s.surface.get(), bo);
    return r;
  }
  return {};
}

Result<void> KmsOutput::setDisplayPower(bool on) {
  State& s = *state_;
  if (on == s.displayOn) return {};
  if (s.pending) {
    if (auto r = waitForFlip(1000); !r) return r;
  }
  int rc = 0;
  if (s.atomic && s.modesetDone) {
    auto* fb = s.onScreen ? static_cast<BoFramebuffer*>(gbm_bo_get_user_data(s.onScreen)) : nullptr;
    rc = s.atomicModeset(fb ? fb->id : 0, on, 0);
  } else if (s.dpmsProperty) {
    rc = drmModeConnectorSetProperty(s.fd.get(), s.connectorId, s.dpmsProperty,
                                     on ? DRM_MODE_DPMS_ON : DRM_MODE_DPMS_OFF);
  } else {
    return fail(Errc::kUnsupported,
                fmt::format("{} has no DPMS property; the display cannot be switched off", s.connector));
  }
  if (rc != 0) {
    return fail(Errc::kIo, fmt::format("switching {} {} failed: {}", s.connector, on ? "on" : "off", errnoText(errno)));
  }
  s.displayOn = on;
  return {};
}

Result<void> KmsOutput::readScanout(Image& out) {
  State& s = *state_;
  if (!s.onScreen) return fail(Errc::kUnavailable, "nothing has been shown yet");
  const std::uint32_t width = s.mode.width;
  const std::uint32_t height = s.mode.height;
  if (out.width != width || out.height != height || out.channels != 4 || out.type != ChannelType::kU8) {
    out = Image::make(width, height, 4);
  }
  const auto convert = [&](const std::uint8_t* base, std::uint32_t stride) {
    // XRGB8888 is little-endian B, G, R, X in memory.
    for (std::uint32_t y = 0; y < height; ++y) {
      const std::uint8_t* src = base + std::size_t{stride} * y;
      std::uint8_t* dst = out.row(y);
      for (std::uint32_t x = 0; x < width; ++x, src += 4, dst += 4) {
        dst[0] = src[2];
        dst[1] = src[1];
        dst[2] = src[0];
        dst[3] = 255;
      }
    }
  };
  // The CRTC's framebuffer as the kernel reports it, mapped as a dumb buffer: what the display
  // scans out, not what Basalt believes it flipped to.
  drm::Crtc crtc(drmModeGetCrtc(s.fd.get(), s.crtcId));
  if (crtc && crtc->buffer_id) {
    drm::Framebuffer fb(drmModeGetFB(s.fd.get(), crtc->buffer_id));
    drm_mode_map_dumb map{};
    map.handle = fb ? fb->handle : 0;
    if (fb && fb->handle && fb->width >= width && fb->height >= height &&
        drmIoctl(s.fd.get(), DRM_IOCTL_MODE_MAP_DUMB, &map) == 0) {
      const std::size_t bytes = std::size_t{fb->pitch} * fb->height;
      void* data = ::mmap(nullptr, bytes, PROT_READ, MAP_SHARED, s.fd.get(), static_cast<off_t>(map.offset));
      if (data != MAP_FAILED) {
        convert(static_cast<const std::uint8_t*>(data), fb->pitch);
        ::munmap(data, bytes);
        return {};
      }
    }
  }
  // Otherwise map the GBM buffer on screen (drivers whose buffers are not dumb buffers).
  std::uint32_t stride = 0;
  void* mapData = nullptr;
  void* data = gbm_bo_map(s.onScreen, 0, 0, width, height, GBM_BO_TRANSFER_READ, &stride, &mapData);
  if (!data) return fail(Errc::kUnsupported, fmt::format("the scan-out buffer on {} cannot be mapped", s.devicePath));
  convert(static_cast<const std::uint8_t*>(data), stride);
  gbm_bo_unmap(s.onScreen, mapData);
  return {};
}

}  // namespace basalt::render
