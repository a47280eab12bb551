#pragma once
// Ray-VR's G-buffer pre-pass: both eyes' primary visibility rasterised by Vulkan in one multiview
// pass (GBufferViews), each eye with its own asymmetric projection from the rig's field of view, sampled at the
// pixel centres the eye pass's first sample goes through. It writes a visibility buffer (per
// pixel the triangle and its barycentrics, primary_hits.h) into one buffer the eye pass reads:
// host-visible memory for the CPU backend, or device memory exported to CUDA (opaque file
// descriptors) with semaphores that order the pass against CUDA's reads of it.
//
// Reversed-Z with an infinite far plane (D32_SFLOAT), no culling (rays see both sides), and every
// triangle drawn: a triangle that cuts texels out is recorded like any other and its pixels are
// traced instead (rasterisedFirstHit), so the result never differs from the ray's in kind.
#include <cstdint>
#include <memory>
#include <string>

#include "pvr/camera/stereo_rig.h"
#include "pvr/shading/primary_hits.h"
#include "pvr/vulkan/vulkan_context.h"

namespace pvr {

class Scene;

// The eye's clip-space transform (column-major, as GLSL's mat4): view-space x and y mapped so that
// pixel (px, py) of EyeCamera::generateRay lands on framebuffer position (px, py); depth is
// near / view depth (reversed, infinite far).
void rasterWorldToClip(const EyeCamera& camera, float nearDepth, float out[16]);

// How the eyes are drawn: both in one multiview pass (VK_KHR_multiview, the default), or a pass
// per eye. Auto: multiview, but a pass per eye on a CPU device: lavapipe (Mesa 22.3) puts
// triangles it clips at the near plane into the wrong view under multiview (measured: a turned
// head's left eye showed the right eye's walls; each view alone is exact).
enum class GBufferViews : int { Auto = 0, Multiview = 1, PassPerView = 2 };

// The buffer's layout: [triangle ids of the left eye, of the right eye, barycentrics left, right].
size_t gbufferBytes(int width, int height);
// One eye's view into such a buffer at `base` (host or device memory).
PrimaryHitsView gbufferEyeView(const void* base, int width, int height, Eye eye);

class GBufferRaster {
 public:
  // Uploads the scene's triangles. shareWithCuda: the buffer and the semaphores are exportable
  // (the device must canShareWithCuda); else the buffer is host-visible. Throws pvr::Error with one
  // line: a device without multiview or the formats, out of memory.
  GBufferRaster(VulkanContext& vk, const Scene& scene, bool shareWithCuda, GBufferViews views = GBufferViews::Auto);
  ~GBufferRaster();
  GBufferRaster(const GBufferRaster&) = delete;
  GBufferRaster& operator=(const GBufferRaster&) = delete;

  // Rasterises both eyes (same size) into the buffer. Shared with CUDA: waits on readersDone() if
  // `waitForReaders` (CUDA signalled it after reading the last frame's buffer) and signals
  // rasterDone() when written. The host path: call waitDone() before reading hostView().
  void render(const EyeCamera eyes[2], bool waitForReaders = false);
  void waitDone();  ///< the host waits for the last render (at most 10 s)
  PrimaryHitsView hostView(Eye eye) const;  ///< host-visible path, after waitDone()
  // The last render's GPU time (timestamps; waits for it); drawMs: of it, the raster passes (the
  // rest copies the targets into the buffer).
  double lastGpuMs(double* drawMs = nullptr);

  // The shared buffer (laid out as gbufferEyeView reads it).
  bool sharedWithCuda() const { return shared_; }
  int width() const { return width_; }
  int height() const { return height_; }
  uint64_t bufferGeneration() const { return generation_; }  ///< changes when the buffer is made anew
  int exportBufferFd() const;     ///< a new descriptor of the buffer's memory (the importer owns it)
  size_t bufferAllocationBytes() const;
  size_t bufferBytes() const;
  int exportRasterDoneFd() const;   ///< binary semaphore Vulkan signals after each render
  int exportReadersDoneFd() const;  ///< binary semaphore CUDA signals after reading
  std::string deviceName() const { return vk_.deviceName(); }
  std::string describe() const;  ///< how and where it draws
  bool multiview() const;

 private:
  struct Impl;
  VulkanContext& vk_;
  std::unique_ptr<Impl> impl_;
  bool shared_ = false;
  int width_ = 0, height_ = 0;
  uint64_t generation_ = 0;
  float nearDepth_ = 1e-4f;
  void resize(int width, int height);
};

}  // namespace pvr
