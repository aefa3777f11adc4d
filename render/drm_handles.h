#pragma once

/// \file
/// \brief One owner per libdrm and GBM handle (private to render/): `std::unique_ptr` aliases
/// whose deleters call the library's free function.

#include <gbm.h>
#include <xf86drm.h>
#include <xf86drmMode.h>

#include <memory>

namespace basalt::render::drm {

template <typename T, void (*Free)(T*)>
struct Deleter {
  void operator()(T* p) const {
    if (p) Free(p);
  }
};

using Resources = std::unique_ptr<drmModeRes, Deleter<drmModeRes, drmModeFreeResources>>;
using Connector = std::unique_ptr<drmModeConnector, Deleter<drmModeConnector, drmModeFreeConnector>>;
using Encoder = std::unique_ptr<drmModeEncoder, Deleter<drmModeEncoder, drmModeFreeEncoder>>;
using Crtc = std::unique_ptr<drmModeCrtc, Deleter<drmModeCrtc, drmModeFreeCrtc>>;
using PlaneResources = std::unique_ptr<drmModePlaneRes, Deleter<drmModePlaneRes, drmModeFreePlaneResources>>;
using Plane = std::unique_ptr<drmModePlane, Deleter<drmModePlane, drmModeFreePlane>>;
using ObjectProperties =
    std::unique_ptr<drmModeObjectProperties, Deleter<drmModeObjectProperties, drmModeFreeObjectProperties>>;
using Property = std::unique_ptr<drmModePropertyRes, Deleter<drmModePropertyRes, drmModeFreeProperty>>;
using Framebuffer = std::unique_ptr<drmModeFB, Deleter<drmModeFB, drmModeFreeFB>>;
using AtomicRequest = std::unique_ptr<drmModeAtomicReq, Deleter<drmModeAtomicReq, drmModeAtomicFree>>;
using GbmDevice = std::unique_ptr<gbm_device, Deleter<gbm_device, gbm_device_destroy>>;
using GbmSurface = std::unique_ptr<gbm_surface, Deleter<gbm_surface, gbm_surface_destroy>>;

}  // namespace basalt::render::drm
