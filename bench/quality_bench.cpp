#include "quality_bench.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>

#include "bench_util.h"
#include "pvr/app/options.h"
#include "pvr/image/image_compare.h"
#include "pvr/image/image_io.h"
#include "pvr/reference/progressive_reference.h"
#include "pvr/render/renderer.h"
#include "pvr/scene/scene.h"
#include "pvr/util/latency_stats.h"

namespace pvr {
namespace {

constexpr int kHz = 90;
constexpr int kMovingFrames = 2 * kHz;  // the 2 s trajectory
constexpr int kStillFrames = 5 * kHz;
constexpr int kAfterStill = 30;  // moving frames after the still head: the return to the real-time path
// Moving head: consecutive pairs of frames compared with their references (relMSE at every one,
// flicker within each pair).
constexpr int kSampledPairs[] = {30, 75, 120, 165};

// A 2 s sway-and-turn from `start`: 5 cm side to side and back, a 1.5 cm bob at twice the rate,
// the head turning 12 degrees left and right and nodding 3 degrees.
Pose swayAndTurn(const Pose& start, int frame) {
  const float phase = 2.0f * kPi * float(frame) / float(kMovingFrames);
  const float deg = kPi / 180.0f;
  Pose p;
  p.position = start.toWorldPoint({0.05f * std::sin(phase), 0.015f * std::sin(2.0f * phase), 0.0f});
  p.orientation = start.orientation * Quat::fromAxisAngle({0, 1, 0}, 12.0f * deg * std::sin(phase)) *
                  Quat::fromAxisAngle({1, 0, 0}, 3.0f * deg * std::sin(2.0f * phase));
  return p;
}

struct Variant {
  const char* name;
  bool denoise, taa;
  int photonBatches;  ///< a rolling photon map's slices (1: every photon every frame)
  bool freshNoise = true;  ///< new random numbers every frame (the default under TAA or the denoiser)
  PixelSampling sampling = PixelSampling::BlueNoise;
  Boundary boundary = Boundary::Sphere;  ///< the estimate where surfaces meet walls or end (photon/boundary.h)
  StereoMode stereo = StereoMode::Separate;
  bool bicubicHistory = DenoiseParams().bicubicHistory;  ///< the denoiser's history read (--denoise-history)
  int iterations = DenoiseParams().iterations;           ///< a-trous passes (--denoise-iterations)
  int directIterations = DenoiseParams().directIterations;  ///< of them, the direct signal's (--denoise-direct-iterations)
  bool quarterPhotonPasses = DenoiseParams().quarterPhotonPasses;  ///< --denoise-photon-passes quarter
  float historyAlpha = DenoiseParams().colourAlpha;  ///< the colour's and the moments' least weight of the current frame
  // The suite's options with this variant's (the moving and the still head both render from it).
  RenderOptions options(const RenderOptions& suite) const {
    RenderOptions o = suite;
    o.denoise.enabled = denoise;
    o.denoise.params.bicubicHistory = bicubicHistory;
    o.denoise.params.iterations = iterations;
    o.denoise.params.directIterations = directIterations;
    o.denoise.params.quarterPhotonPasses = quarterPhotonPasses;
    o.denoise.params.colourAlpha = o.denoise.params.momentsAlpha = historyAlpha;
    o.temporal.enabled = taa;
    o.stereo = stereo;
    o.photonBatches = photonBatches;
    o.gather.sampling = sampling;
    o.gather.density.boundary = boundary;
    return o;
  }
};
constexpr Variant kVariants[] = {{"raw", false, false, 1},
                                 {"TAA", false, true, 1},
                                 {"denoise", true, false, 1},
                                 {"denoise + TAA", true, true, 1},
                                 {"denoise, rolling 8", true, false, 8},
                                 {"denoise + TAA, rolling 8", true, true, 8},
                                 {"denoise, rolling 16", true, false, 16},
                                 {"denoise, same noise", true, false, 1, false},
                                 // The sampling before blue noise, for comparison.
                                 {"raw, white noise", false, false, 1, true, PixelSampling::White},
                                 {"TAA, white noise", false, true, 1, true, PixelSampling::White},
                                 {"denoise, white noise", true, false, 1, true, PixelSampling::White},
                                 {"denoise + TAA, white noise", true, true, 1, true, PixelSampling::White},
                                 // The estimate clipped at walls and edges (--boundary clipped) against the paper's sphere.
                                 {"raw, clipped", false, false, 1, true, PixelSampling::BlueNoise, Boundary::Clipped},
                                 {"denoise + TAA, clipped", true, true, 1, true, PixelSampling::BlueNoise, Boundary::Clipped},
                                 // The right eye reusing the left eye's shading (and its denoise).
                                 {"raw, gather reuse", false, false, 1, true, PixelSampling::BlueNoise, Boundary::Sphere,
                                  StereoMode::Gather},
                                 {"denoise, gather reuse", true, false, 1, true, PixelSampling::BlueNoise, Boundary::Sphere,
                                  StereoMode::Gather},
                                 // The history read by Catmull-Rom (sharper, dearer) against the default's bilinear.
                                 {"denoise, catmull-rom history", true, false, 1, true, PixelSampling::BlueNoise,
                                  Boundary::Sphere, StereoMode::Separate, true},
                                 // Fewer a-trous passes (cheaper, a smaller footprint).
                                 {.name = "denoise, 4 passes", .denoise = true, .taa = false, .photonBatches = 1, .iterations = 4},
                                 {.name = "denoise, 3 passes", .denoise = true, .taa = false, .photonBatches = 1, .iterations = 3},
                                 // The direct signal through fewer passes than the photon map's (its noise is finer).
                                 {.name = "denoise, direct 3 passes", .denoise = true, .taa = false, .photonBatches = 1,
                                  .directIterations = 3},
                                 {.name = "denoise, direct 2 passes", .denoise = true, .taa = false, .photonBatches = 1,
                                  .directIterations = 2},
                                 {.name = "denoise, direct 2 passes, gather reuse", .denoise = true, .taa = false,
                                  .photonBatches = 1, .stereo = StereoMode::Gather, .directIterations = 2},
                                 // The cheapest of the controller's denoise steps above 2 passes, under reuse.
                                 {.name = "denoise, 4 passes, direct 2, gather reuse", .denoise = true, .taa = false,
                                  .photonBatches = 1, .stereo = StereoMode::Gather, .iterations = 4, .directIterations = 2},
                                 // The photon-map signal's later passes on the even pixels (a quarter), the
                                 // rest interpolated: against the two rows above.
                                 {.name = "denoise, direct 2 passes, quarter photon passes", .denoise = true, .taa = false,
                                  .photonBatches = 1, .directIterations = 2, .quarterPhotonPasses = true},
                                 {.name = "denoise, 4 passes, direct 2, quarter photon passes, gather reuse", .denoise = true,
                                  .taa = false, .photonBatches = 1, .stereo = StereoMode::Gather, .iterations = 4,
                                  .directIterations = 2, .quarterPhotonPasses = true},
                                 // A longer temporal average (the history's least weight 0.1 instead of 0.2, the
                                 // moments' too): less flicker for more lag (docs/denoising.md).
                                 {.name = "denoise, history alpha 0.1", .denoise = true, .taa = false, .photonBatches = 1,
                                  .historyAlpha = 0.1f}};

// The variants the run asked for (--quality-variants; all where empty), each checked: the first,
// "raw", is every ratio's base and always runs.
// The image a variant's eyes are shown (the last stage it runs).
EyeImage shownImage(const Variant& v) {
  return v.taa ? EyeImage::Displayed : v.denoise ? EyeImage::Denoised : EyeImage::Rendered;
}

std::vector<const Variant*> selectedVariants(const std::string& names) {
  const std::vector<std::string> asked = names.empty() ? std::vector<std::string>() : splitList(names, ';');
  for (const std::string& name : asked)
    if (std::none_of(std::begin(kVariants), std::end(kVariants), [&](const Variant& v) { return name == v.name; }))
      throw Error("--quality-variants: no variant '" + name + "' in the quality suite");
  std::vector<const Variant*> out;
  for (const Variant& v : kVariants)
    if (asked.empty() || &v == &kVariants[0] || std::find(asked.begin(), asked.end(), v.name) != asked.end())
      out.push_back(&v);
  return out;
}

// Flicker of shown frames a -> b where the reference does not change: the mean absolute change of
// luminance over the pixels whose references differ by less than 2 % (and 0.002 absolute), over
// the references' mean luminance there. Those pixels still change a little in the reference (a
// moving head sees a slightly different view): that floor, and the change the reference does not
// explain (mean |(b - a) - (reference b - reference a)|), come with it.
struct Flicker {
  double shown = 0, reference = 0, unexplained = 0;
};
Flicker flicker(const Image& a, const Image& b, const Image& referenceA, const Image& referenceB) {
  double shown = 0, truth = 0, unexplained = 0, level = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    const double ra = luminance(referenceA.pixels[i]), rb = luminance(referenceB.pixels[i]);
    if (std::fabs(ra - rb) > 0.02 * std::max(ra, rb) + 0.002) continue;
    const double d = double(luminance(b.pixels[i])) - luminance(a.pixels[i]);
    shown += std::fabs(d);
    truth += std::fabs(rb - ra);
    unexplained += std::fabs(d - (rb - ra));
    level += 0.5 * (ra + rb);
  }
  if (level <= 0) return {};
  return {shown / level, truth / level, unexplained / level};
}

// Mean absolute change of luminance from a to b over a's mean luminance.
double change(const Image& a, const Image& b) {
  double diff = 0, level = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i)
    diff += std::fabs(double(luminance(b.pixels[i])) - luminance(a.pixels[i])), level += luminance(a.pixels[i]);
  return level > 0 ? diff / level : 0.0;
}

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0.0 : s / double(v.size());
}

// The centre of an image, at most size x size (the docs' side-by-side crops).
Image centreCrop(const Image& image, int size) {
  const int w = std::min(size, image.width), h = std::min(size, image.height);
  const int x0 = (image.width - w) / 2, y0 = (image.height - h) / 2;
  Image out(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) out.pixels[size_t(y) * w + x] = image.pixels[size_t(y + y0) * image.width + x + x0];
  return out;
}
constexpr int kCrop = 480;

bool isSampled(int frame) {
  for (int f : kSampledPairs)
    if (frame == f || frame == f + 1) return true;
  return false;
}

}  // namespace

int runQuality(const FrameBenchArgs& args, BackendKind kind, nlohmann::json& json) {
  int failures = 0;
  const std::vector<const Variant*> variants = selectedVariants(args.qualityVariants);
  if (args.referencePasses < 2 || args.referencePasses > kMaxReferencePasses / 4)
    throw Error("--reference-passes must be between 2 and " + std::to_string(kMaxReferencePasses / 4));
  std::printf("\nImage quality at the real-time settings (512x512 photons, 1 sample per pixel, full shading, hash grid, "
              "hybrid kernel; the random numbers change every frame under TAA or the denoiser): the shown image "
              "against the converged reference of the same view (%d progressive passes of 1024x1024 photons, hash grid, "
              "a shadow ray to every light, pixel centres; 4x the passes for the still head).\n"
              "Moving head: a 2 s sway-and-turn at %d Hz (%d frames), relMSE averaged over %zu sampled frames of "
              "both eyes, flicker (mean |change| of luminance between consecutive frames where the reference does "
              "not change, over its mean there; beside it the reference's own change there, and the change the "
              "reference does not explain: mean |shown change - reference change|) over %zu pairs. Still head: %d frames (5 s) at the first pose.\n\n",
              args.referencePasses, kHz, kMovingFrames, 2 * std::size(kSampledPairs), std::size(kSampledPairs),
              kStillFrames);
  for (const std::string& name : splitList(args.qualityScenes)) {
    Scene scene;
    try {
      scene = loadScene(name);
    } catch (const Error& e) {
      std::printf("| %s | skipped: %s |\n", name.c_str(), e.what());
      continue;
    }
    const StereoRig start = [&] {
      StereoRig rig = scene.rig;
      if (!args.eyeSize.empty()) setEyeSize(rig, args.eyeSize);
      return rig;
    }();
    const std::vector<std::string> builtins = builtinSceneNames();
    const bool builtin = std::find(builtins.begin(), builtins.end(), name) != builtins.end();
    RenderOptions o;
    o.photonsX = o.photonsY = 512;
    o.gather.density.radius = builtin ? RenderOptions().gather.density.radius : args.sceneRadius;
    o.gather.mode = ShadingMode::Full;
    RenderOptions ro = o;
    ro.photonsX = ro.photonsY = 1024;
    ro.gather.punctualShadowRays = 0;
    ReferenceSettings centres;
    centres.boxFilter = false;
    std::unique_ptr<FrameRenderer> referenceRenderer = makeFrameRenderer(kind, scene);
    auto reference = [&](const Pose& head, int passes, Image out[2], double estimated[2], uint32_t seed = 0x5eed) {
      StereoRig rig = start;
      rig.head = head;
      for (;;) {
        try {
          RenderOptions seeded = ro;
          seeded.gather.seed = seed;
          ProgressiveReference r(*referenceRenderer, rig, seeded, centres);
          for (int i = 0; i < passes; ++i) r.addPass();
          for (int e = 0; e < 2; ++e) out[e] = r.image(Eye(e)), estimated[e] = r.estimatedRelMse(Eye(e));
          return;
        } catch (const Error& e) {
          // The shrinking radius can outgrow the hash grid's cell limit on a large extent: the
          // kd-tree has none (and is built on the host: slower).
          if (ro.map == PhotonMapKind::KdTree) throw;
          std::printf("| %s | reference: the hash grid refused (%s): kd-tree |\n", scene.name.c_str(), e.what());
          ro.map = PhotonMapKind::KdTree;
        }
      }
    };

    // Moving head.
    std::vector<int> sampled;
    for (int f : kSampledPairs) sampled.push_back(f), sampled.push_back(f + 1);
    std::vector<std::array<Image, 2>> references(sampled.size());
    double worstEstimate = 0;
    for (size_t s = 0; s < sampled.size(); ++s) {
      double estimated[2];
      reference(swayAndTurn(start.head, sampled[s]), args.referencePasses, references[s].data(), estimated);
      worstEstimate = std::max({worstEstimate, estimated[0], estimated[1]});
    }
    // The metric's floor: a second reference of the same views from other random numbers, compared
    // as a shown image would be. Its flicker the reference does not explain is the two references'
    // own noise (each pair of views shares its numbers, so much of it cancels within a pair).
    double floorRelMse = 0, floorUnexplained = 0;
    {
      std::vector<double> relMse, unexplained;
      std::vector<std::array<Image, 2>> other(sampled.size());
      for (size_t s = 0; s < sampled.size(); ++s) {
        double estimated[2];
        reference(swayAndTurn(start.head, sampled[s]), args.referencePasses, other[s].data(), estimated, 0x0dd5eed);
        for (int e = 0; e < 2; ++e) relMse.push_back(compareToReference(other[s][e], references[s][e]).relMse);
      }
      for (size_t s = 0; s + 1 < sampled.size(); s += 2)
        for (int e = 0; e < 2; ++e)
          unexplained.push_back(flicker(other[s][e], other[s + 1][e], references[s][e], references[s + 1][e]).unexplained);
      floorRelMse = mean(relMse), floorUnexplained = mean(unexplained);
    }
    std::printf("| %s | %dx%d per eye | radius %g | references: %zu views, estimated relMSE (variance) at most %.2g | "
                "a second reference from other numbers: relMSE %.5f, flicker the reference does not explain %.4f (the "
                "metric's floor) |\n\n",
                scene.name.c_str(), start.width, start.height, o.gather.density.radius, sampled.size(), worstEstimate,
                floorRelMse, floorUnexplained);
    json.push_back({{"suite", "quality"}, {"scene", scene.name}, {"head", "moving"}, {"variant", "second reference"},
                    {"eye_size", {start.width, start.height}}, {"reference_passes", args.referencePasses},
                    {"rel_mse_vs_reference", floorRelMse}, {"unexplained_flicker", floorUnexplained}});
    std::printf("| scene | variant | relMSE (moving) | of raw | SSIM | flicker | of raw | reference's flicker | "
                "flicker the reference does not explain | of raw | denoise ms / stereo frame (mean / p99) | "
                "frame ms (mean / p99) | check |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    double rawRelMse = 0, rawFlicker = 0, rawUnexplained = 0;
    for (const Variant* variant : variants) {
      const Variant& v = *variant;
      std::unique_ptr<FrameRenderer> renderer = makeFrameRenderer(kind, scene);
      const RenderOptions vo = v.options(o);
      renderer->setFreshNoisePerFrame(v.freshNoise);
      std::vector<double> denoiseMs, frameMs, relMse, ssim, flickers, referenceFlickers, unexplained;
      std::vector<std::array<Image, 2>> shown(sampled.size());
      for (int f = 0; f < kMovingFrames; ++f) {
        StereoRig rig = start;
        rig.head = swayAndTurn(start.head, f);
        const bool keep = isSampled(f);
        FrameResult r = renderer->render(rig, vo, keep);
        denoiseMs.push_back(r.timings.denoiseMs[0] + r.timings.denoiseMs[1]);
        frameMs.push_back(r.timings.totalMs());
        if (!keep) continue;
        const size_t s = size_t(std::find(sampled.begin(), sampled.end(), f) - sampled.begin());
        for (int e = 0; e < 2; ++e) {
          shown[s][e] = std::move(r.eyes[e].image);
          const ReferenceError err = compareToReference(shown[s][e], references[s][e]);
          relMse.push_back(err.relMse);
          ssim.push_back(err.ssim);
        }
      }
      for (size_t s = 0; s + 1 < sampled.size(); s += 2)
        for (int e = 0; e < 2; ++e) {
          const Flicker f = flicker(shown[s][e], shown[s + 1][e], references[s][e], references[s + 1][e]);
          flickers.push_back(f.shown), referenceFlickers.push_back(f.reference), unexplained.push_back(f.unexplained);
        }
      const double m = mean(relMse), fl = mean(flickers), un = mean(unexplained);
      if (&v == &kVariants[0]) rawRelMse = m, rawFlicker = fl, rawUnexplained = un;  // "raw"
      const LatencyStats dn = latencyStats(denoiseMs), fr = latencyStats(frameMs);
      // Every variant must stay near the reference (a broken path shows here), and the denoiser
      // must bring the image closer than the raw frame.
      const bool ok = m < 1.0 && (!v.denoise || m < rawRelMse);
      failures += ok ? 0 : 1;
      std::printf("| %s | %s | %.5f | %.3f | %.3f | %.4f | %.3f | %.4f | %.4f | %.3f | %s | %s | %s |\n",
                  scene.name.c_str(), v.name, m, rawRelMse > 0 ? m / rawRelMse : 1.0, mean(ssim), fl,
                  rawFlicker > 0 ? fl / rawFlicker : 1.0, mean(referenceFlickers), un,
                  rawUnexplained > 0 ? un / rawUnexplained : 1.0, v.denoise ? meanP99(dn, 3).c_str() : "-", meanP99(fr, 2).c_str(), ok ? "ok" : "MISMATCH");
      if (!args.qualityImages.empty()) {
        const std::string prefix = args.qualityImages + "_" + scene.name + "_moving_";
        std::string tag = v.name;
        std::replace(tag.begin(), tag.end(), ' ', '_');
        std::replace(tag.begin(), tag.end(), '+', 'p');
        tag.erase(std::remove(tag.begin(), tag.end(), ','), tag.end());
        writePng(centreCrop(shown[2][0], kCrop), prefix + tag + ".png");
        if (!v.denoise && !v.taa) writePng(centreCrop(references[2][0], kCrop), prefix + "reference.png");
      }
      json.push_back({{"suite", "quality"}, {"scene", scene.name}, {"head", "moving"}, {"variant", v.name},
                      {"photon_batches", v.photonBatches}, {"backend", renderer->name()}, {"device", renderer->deviceName()},
                      {"eye_size", {start.width, start.height}}, {"photons", 512 * 512},
                      {"radius", o.gather.density.radius}, {"frames", kMovingFrames}, {"sampled_frames", sampled},
                      {"rel_mse_vs_reference", m}, {"rel_mse_of_raw", rawRelMse > 0 ? m / rawRelMse : 1.0},
                      {"ssim_vs_reference", mean(ssim)}, {"flicker", fl},
                      {"flicker_of_raw", rawFlicker > 0 ? fl / rawFlicker : 1.0},
                      {"reference_flicker", mean(referenceFlickers)}, {"unexplained_flicker", un},
                      {"unexplained_flicker_of_raw", rawUnexplained > 0 ? un / rawUnexplained : 1.0},
                      {"fresh_noise", v.freshNoise},
                      {"sampling", v.sampling == PixelSampling::BlueNoise ? "blue-noise" : "white"},
                      {"boundary", v.boundary == Boundary::Clipped ? "clipped" : "sphere"},
                      {"stereo", stereoModeName(v.stereo)}, {"history", v.bicubicHistory ? "catmull-rom" : "bilinear"},
                      {"denoise_iterations", v.iterations}, {"denoise_direct_iterations", v.directIterations},
                      {"denoise_photon_passes", v.quarterPhotonPasses ? "quarter" : "full"},
                      {"history_alpha", v.historyAlpha}, {"denoise_ms", dn},
                      {"frame_ms", fr}, {"reference_passes", args.referencePasses},
                      {"reference_estimated_rel_mse_max", worstEstimate}, {"check", ok ? "ok" : "MISMATCH"}});
    }

    // Still head.
    if (!args.qualityStill) {
      std::printf("\n");
      continue;
    }
    Image still[2];
    double estimated[2];
    reference(start.head, 4 * args.referencePasses, still, estimated);
    std::printf("\n| scene | still head | relMSE frame 1 | after 1 s (90) | of frame 1 | after 5 s (450) | PSNR after 5 s | "
                "SSIM after 5 s | then moving: largest change in 10 frames / moving median | check |\n"
                "|---|---|---|---|---|---|---|---|---|---|\n");
    for (const Variant* variant : variants) {
      const Variant& v = *variant;
      if (v.taa && !v.denoise) continue;  // TAA alone is the moving head's business
      // A still head retraces every photon each frame anyway, and refines with new numbers.
      if (v.photonBatches > 1 || !v.freshNoise) continue;
      // A still head reads its history at pixel centres, where both reads agree.
      if (v.bicubicHistory != DenoiseParams().bicubicHistory) continue;
      std::unique_ptr<FrameRenderer> renderer = makeFrameRenderer(kind, scene);
      const RenderOptions vo = v.options(o);
      ReferenceError at[3];
      size_t nonFinite[3] = {0, 0, 0};  // pixels of both eyes at each compared frame
      Image last, stillShown;
      std::vector<double> changes;  // after the still frames, moving: frame-to-frame change of the left eye
      DeviceImageCheck deviceCheck;  // on the GPU every still frame is checked there
      int firstNonFinite = -1;
      for (int f = 0; f < kStillFrames + kAfterStill; ++f) {
        if (f >= kStillFrames) {
          StereoRig rig = start;
          rig.head = swayAndTurn(start.head, f - kStillFrames + 1);
          FrameResult r = renderer->render(rig, vo, true);
          changes.push_back(change(last, r.eyes[0].image));
          last = std::move(r.eyes[0].image);
          continue;
        }
        const int slot = f == 0 ? 0 : f == kHz - 1 ? 1 : f == kStillFrames - 1 ? 2 : -1;
        FrameResult r = renderer->render(start, vo, slot >= 0);
        // Shown and as the eye pass rendered them (the denoiser counts a non-finite sample as black).
        uint64_t counts[2], rendered[2];
        const size_t pixels = size_t(start.width) * size_t(start.height);
        deviceCheck.nonFinitePixels(*renderer, pixels, counts);
        deviceCheck.nonFinitePixels(*renderer, pixels, EyeImage::Rendered, rendered);
        if ((counts[0] || counts[1] || rendered[0] || rendered[1]) && firstNonFinite < 0) {
          firstNonFinite = f;
          std::printf("| %s | %s | first non-finite pixels at still frame %d (still %d): %s |\n", scene.name.c_str(), v.name,
                      f, renderer->stillFrames(), describeNonFinitePixels(*renderer, shownImage(v), v.stereo != StereoMode::Separate).c_str());
        }
        if (slot < 0) continue;
        for (int e = 0; e < 2; ++e) nonFinite[slot] += nonFinitePixels(r.eyes[e].image);
        ReferenceError e[2] = {compareToReference(r.eyes[0].image, still[0]), compareToReference(r.eyes[1].image, still[1])};
        at[slot] = e[0];
        at[slot].relMse = 0.5 * (e[0].relMse + e[1].relMse);
        at[slot].psnr = 0.5 * (e[0].psnr + e[1].psnr);
        at[slot].ssim = 0.5 * (e[0].ssim + e[1].ssim);
        if (slot == 2) last = std::move(r.eyes[0].image), stillShown = last;
      }
      // The return to the moving head: the largest frame-to-frame change in its first 10 frames
      // over the median change of the 20 after them (1: no pop beyond what motion changes anyway).
      std::vector<double> settled(changes.begin() + 10, changes.end());
      std::sort(settled.begin(), settled.end());
      const double median = settled.empty() ? 0.0 : settled[settled.size() / 2];
      const double pop = median > 0 ? *std::max_element(changes.begin(), changes.begin() + 10) / median : 0.0;
      const size_t anyNonFinite = nonFinite[0] + nonFinite[1] + nonFinite[2];
      const bool ok = at[2].relMse < 1.0 && (!v.denoise || at[2].relMse < at[0].relMse) && anyNonFinite == 0 && firstNonFinite < 0;
      if (anyNonFinite)
        std::printf("| %s | %s | non-finite pixels (both eyes) at frame 1, after 1 s, after 5 s: %zu, %zu, %zu |\n",
                    scene.name.c_str(), v.name, nonFinite[0], nonFinite[1], nonFinite[2]);
      failures += ok ? 0 : 1;
      std::printf("| %s | %s | %.5f | %.5f | %.3f | %.5f | %.1f dB | %.3f | %.2f | %s |\n", scene.name.c_str(), v.name,
                  at[0].relMse, at[1].relMse, at[0].relMse > 0 ? at[1].relMse / at[0].relMse : 1.0, at[2].relMse,
                  at[2].psnr, at[2].ssim, pop, ok ? "ok" : "MISMATCH");
      if (!args.qualityImages.empty()) {
        std::string tag = v.name;
        std::replace(tag.begin(), tag.end(), ' ', '_');
        std::replace(tag.begin(), tag.end(), '+', 'p');
        writePng(centreCrop(stillShown, kCrop), args.qualityImages + "_" + scene.name + "_still_" + tag + ".png");
        if (!v.denoise) writePng(centreCrop(still[0], kCrop), args.qualityImages + "_" + scene.name + "_still_reference.png");
      }
      json.push_back({{"suite", "quality"}, {"scene", scene.name}, {"head", "still"}, {"variant", v.name},
                      {"sampling", v.sampling == PixelSampling::BlueNoise ? "blue-noise" : "white"},
                      {"boundary", v.boundary == Boundary::Clipped ? "clipped" : "sphere"},
                      {"backend", renderer->name()}, {"device", renderer->deviceName()},
                      {"eye_size", {start.width, start.height}}, {"photons", 512 * 512},
                      {"radius", o.gather.density.radius}, {"frames", kStillFrames},
                      {"rel_mse_frame_1", at[0].relMse}, {"rel_mse_1s", at[1].relMse}, {"rel_mse_5s", at[2].relMse},
                      {"psnr_5s_db", at[2].psnr}, {"ssim_5s", at[2].ssim}, {"return_to_moving_pop", pop},
                      {"non_finite_pixels", {nonFinite[0], nonFinite[1], nonFinite[2]}},
                      {"return_changes", changes},
                      {"reference_passes", 4 * args.referencePasses},
                      {"reference_estimated_rel_mse", {estimated[0], estimated[1]}}, {"check", ok ? "ok" : "MISMATCH"}});
    }
    std::printf("\n");
  }
  return failures;
}

}  // namespace pvr
