#pragma once
// The stages a backend implements (CPU: Embree + TBB; CUDA), and what each reads and writes.
// The frame's order lives in one place, FrameRenderer (frame_renderer.h), which calls these;
// a backend holds the frame's buffers (host or device memory) between the calls.
//
//   stage          reads                                        writes
//   photon trace   scene                                        Photons
//   primary        scene (rasterised, both eyes)                PrimaryHits
//   map build      Photons                                      PhotonMap
//   scatter        SourceSurfaces                               ScatteredSurfaces
//   eye pass       PhotonMap; raster: PrimaryHits; reuser:     RenderedImage, InverseDepth;
//                  SourceSurfaces, the left RenderedImage,      full: FirstHits; foveated:
//                  (scatter) ScatteredSurfaces                  SampleSpacing; source:
//                                                               SourceSurfaces; full reuser:
//                                                               ReusedFrom; full, denoising:
//                                                               DenoiseGuides
//   denoise        RenderedImage, InverseDepth; full:           DenoisedImage (and the eye's
//                  DenoiseGuides; foveated: SampleSpacing;      history)
//                  full reuser: ReusedFrom, the left
//                  DenoiseGuides and DenoisedImage
//   temporal       RenderedImage (denoised: DenoisedImage),     DisplayedImage (and the eye's
//                  InverseDepth, (foveated) SampleSpacing,      history)
//                  the eye's history
//
// FrameDataflow checks these declarations while a frame runs: a stage that would read what no
// earlier stage wrote this frame is an error, and a frame's results hold exactly what was written.
#include <cstddef>
#include <string>
#include <vector>

#include "pvr/pipeline/frame_options.h"
#include "pvr/pipeline/frame_result.h"
#include "pvr/pipeline/stage_clock.h"

namespace pvr {

// An eye's part in stereo reuse.
enum class StereoRole : int {
  Alone = 0,   ///< separate rendering
  Source = 1,  ///< the left eye under reuse: records its surfaces for the right eye
  Reuser = 2,  ///< the right eye under reuse: takes the left eye's shading where it may
};

// One eye pass: everything the backend needs to shade one eye, full or foveated.
struct EyePass {
  Eye eye = Eye::Left;
  EyeCamera camera;
  GatherParams gather;
  PhotonMapKind map = PhotonMapKind::HashGrid;
  DensityKernel kernel = DensityKernel::Hybrid;
  DensityScheme density = DensityScheme::PerPixel;
  float cacheCellSize = 0.0f;  ///< the surface cache's cell side (scene units)
  StereoRole role = StereoRole::Alone;
  bool rasterPrimary = false;  ///< sample 0's first hits from the frame's G-buffer pre-pass (rasterizePrimary)
  RaySchedule raySchedule = RaySchedule::Auto;  ///< the GPU's (RenderOptions)
  StereoMode reuse = StereoMode::Separate;  ///< the reuser's: scatter or gather
  EyeCamera source;                          ///< the reuser's: the eye it reuses (the left)
  const FoveationMask* mask = nullptr;       ///< foveated: the mask, placed at the gaze pixel
  int gazeX = 0, gazeY = 0;
  bool denoiseGuides = false;  ///< full resolution: also write the guides (emitted and direct parts, albedo, normal)
  int stillFrames = 0;         ///< frames the view has been still before this one (the denoiser's refinement)
  bool foveated() const { return mask != nullptr; }
};

// What the temporal stage resolves for one eye.
struct TemporalPass {
  Eye eye = Eye::Left;
  EyeCamera camera;
  TaaParams params;
  bool foveated = false;
  bool denoised = false;      ///< the denoised image (else the rendered one)
  bool emittedApart = false;  ///< the eye pass wrote its guides: their emitted part is shown as rendered
  bool reuser = false;        ///< the right eye under full-resolution reuse: reused pixels' emitted part is the left's
};

// What the pass reads of the eye it reuses, from that eye's buffers as the backend holds them
// (host or device pointers); empty unless the pass is the reuser.
inline StereoReuseView reuseViewFor(const EyePass& pass, const SurfaceRecord* sourceSurfaces, const Vec3* sourceImage,
                                    const uint64_t* scattered) {
  StereoReuseView reuse;
  if (pass.role != StereoRole::Reuser) return reuse;
  reuse.mode = pass.reuse;
  reuse.source = pass.source;
  reuse.sourceSurfaces = sourceSurfaces;
  reuse.sourceImage = sourceImage;
  reuse.scattered = pass.reuse == StereoMode::Scatter ? scattered : nullptr;
  return reuse;
}

// Buffers that flow between stages. Photons, PhotonMap and the two surface buffers are the
// frame's; the rest exist per eye.
enum class FrameData : int {
  Photons = 0,
  PhotonMap,
  PrimaryHits,        ///< per pixel of each eye, the rasterised first hit (the G-buffer pre-pass)
  SourceSurfaces,     ///< per left pixel: the surface the right eye may reuse
  ScatteredSurfaces,  ///< per right pixel: the nearest left surface projected there
  RenderedImage,      ///< the eye's image as shaded (what the reuser reads of the left eye)
  InverseDepth,       ///< per pixel, 1 / view depth
  FirstHits,          ///< per pixel, the first triangle hit (full resolution)
  SampleSpacing,      ///< per pixel, the foveated samples' spacing
  ReusedFrom,         ///< per right pixel, the left pixel it took its shading from
  DenoiseGuides,      ///< per pixel, the denoiser's: direct part, demodulation albedo, normal
  DenoisedImage,      ///< after the denoiser
  DisplayedImage,     ///< after TAA
  Count,
};
const char* frameDataName(FrameData data);

struct DataRef {
  FrameData data;
  int eye = kWholeFrame;
};

struct StageIO {
  Stage stage;
  std::vector<DataRef> reads, writes;
};

StageIO photonTraceIO();
StageIO primaryIO(const bool eyes[2]);
StageIO mapBuildIO();
StageIO scatterIO();
StageIO eyePassIO(const EyePass& pass);
StageIO denoiseIO(const EyePass& pass);
StageIO temporalIO(const TemporalPass& pass);

// What has been written this frame.
class FrameDataflow {
 public:
  // Throws pvr::Error if the stage reads something not written yet; then marks its writes.
  void run(const StageIO& io);
  // Throws pvr::Error naming `reader` (a step between stages, such as vergence) unless written.
  void require(const DataRef& data, const char* reader) const;
  bool has(FrameData data, int eye = kWholeFrame) const { return written_[slot(data, eye)]; }

 private:
  static int slot(FrameData data, int eye) { return int(data) * 3 + eye + 1; }
  bool written_[int(FrameData::Count) * 3] = {};
};

// Which of an eye's outputs to copy out at the end of the frame.
// The images an eye has in a frame, in the order the stages write them.
enum class EyeImage : int { Rendered = 0, Denoised = 1, Displayed = 2 };

struct EyeReadback {
  EyeImage image = EyeImage::Rendered;  ///< the one the eye is shown
  bool firstPrim = false, sampleSpacing = false, reusedFrom = false;
};

struct FrameCounters {
  size_t shadedSamples[2] = {0, 0};  ///< pixels, or mask vertices when foveated
  size_t reusedSamples = 0;           ///< the reuser's samples that took the left eye's shading
  size_t historyPixels[2] = {0, 0};   ///< TAA: pixels that blended in their history
  size_t deviceBytes = 0;             ///< GPU memory held (0 on the CPU)
  size_t cacheCells = 0;              ///< the surface cache's cells this frame (both eyes)
  size_t cacheUnplaced = 0;           ///< points whose cell found no slot in the cache (estimated on their own)
  double primaryDrawMs = 0;           ///< the G-buffer pre-pass's raster passes, GPU time (timestamps)
};

class FrameBackend {
 public:
  virtual ~FrameBackend() = default;
  virtual std::string name() const = 0;  ///< "cpu" or "cuda"
  virtual std::string deviceName() const = 0;
  virtual StageClock& clock() = 0;

  // Photon trace: returns the number of photons stored.
  // Traces params' photons into slot `slot` of `slots`, replacing what it held (a new slot count
  // empties them all); the photon map is built over every slot's photons. Returns how many
  // photons all slots hold.
  virtual size_t tracePhotons(const PhotonTraceParams& params, int slot, int slots) = 0;
  // Map build over the stored photons: returns the map's bytes.
  virtual size_t buildPhotonMap(PhotonMapKind kind, float radius) = 0;
  // The G-buffer pre-pass: both eyes' first hits rasterised at their pixel centres (the eyes of
  // one rig: same size), for the eye passes with rasterPrimary. Times itself (Stage::Primary).
  virtual void rasterizePrimary(const EyeCamera eyes[2]) = 0;
  // Scatter: the source eye's surfaces into the target eye's image.
  virtual void scatter(const EyeCamera& source, const EyeCamera& target) = 0;
  // The eye pass; times its own parts (EyeRays, Density, Reconstruct) on clock() for pass.eye.
  virtual void renderEye(const EyePass& pass) = 0;
  // One value of an eye's inverse depth (vergence needs the left eye's at its gaze); may wait.
  virtual float inverseDepthAt(Eye eye, size_t pixel) = 0;
  // Denoise: the eye's rendered image, guided by its depth and (full resolution) the pass's
  // guides, with the eye's denoising history, into its denoised image. Under full-resolution
  // reuse the right eye's reused pixels show the left eye's denoised colour.
  virtual void denoise(const EyePass& pass, const DenoiseParams& params) = 0;
  // Temporal: blends the eye's rendered (or denoised) image with its history into its displayed image.
  virtual void resolveTemporal(const TemporalPass& pass) = 0;
  virtual void forgetHistory(Eye eye) = 0;  ///< the next resolve starts again
  virtual void forgetDenoiseHistory(Eye eye) = 0;  ///< the next denoise starts again
  // Waits for the frame's work; the clock's times are valid after this.
  virtual FrameCounters finishFrame() = 0;
  virtual void readEye(Eye eye, const EyeReadback& what, EyeResult& out) = 0;
  // One of the eye's images where it lies in GPU memory: linear RGB, row-major, valid until the
  // next frame; null for backends that render on the host.
  virtual const Vec3* deviceImage(Eye eye, EyeImage which) const { return nullptr; }
  // The last frame's per-pixel 1 / view depth of an eye in GPU memory; null on the CPU.
  virtual const float* deviceInverseDepth(Eye eye) const { return nullptr; }
  // The GPU stream the frame's work runs on (cudaStream_t); work queued on it after a frame runs
  // before the next frame's. Null on the CPU.
  virtual void* deviceStream() const { return nullptr; }
};

}  // namespace pvr
