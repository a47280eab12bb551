#include "pvr/frame/frame.h"

#include <cmath>
#include <regex>
#include <string>

#include "pvr/util/error.h"

namespace pvr {
namespace {
constexpr int kMaxEyeDimension = 8192;
}  // namespace

const char* densityKernelName(DensityKernel k) {
  switch (k) {
    case DensityKernel::Single: return "single";
    case DensityKernel::Hybrid: return "hybrid";
    case DensityKernel::SharedMemory: return "shared";
    case DensityKernel::CellSorted: return "sorted";
  }
  return "?";
}

const char* stereoModeName(StereoMode m) {
  switch (m) {
    case StereoMode::Separate: return "separate";
    case StereoMode::Scatter: return "scatter";
    case StereoMode::Gather: return "gather";
  }
  return "?";
}

StereoMode parseStereoMode(const std::string& text, const std::string& what) {
  for (StereoMode m : {StereoMode::Separate, StereoMode::Scatter, StereoMode::Gather})
    if (text == stereoModeName(m)) return m;
  throw Error(what + " must be separate, scatter or gather, got '" + text + "'");
}

void vergeRightGaze(const StereoRig& rig, FoveationOptions& foveation, const float* leftInverseDepthAtGaze) {
  float* right = foveation.gaze[1];
  right[0] = foveation.gaze[0][0], right[1] = foveation.gaze[0][1];
  if (!leftInverseDepthAtGaze) return;
  int gx, gy;
  foveation.gazePixel(0, rig.width, rig.height, gx, gy);
  const EyeCamera left = rig.eye(Eye::Left), rightEye = rig.eye(Eye::Right);
  const float cx = float(gx) + 0.5f, cy = float(gy) + 0.5f, w = *leftInverseDepthAtGaze;
  float px, py;
  bool seen = w > 0.0f ? rightEye.project(left.pointAt(cx, cy, w), px, py)
                       : rightEye.projectDirection(left.pose.toWorldDir(left.localDirection(cx, cy)), px, py);
  if (!seen) return;
  right[0] = std::clamp(px / float(rig.width), 0.0f, 1.0f);
  right[1] = std::clamp(py / float(rig.height), 0.0f, 1.0f);
}

void setEyeSize(StereoRig& rig, const std::string& text) {
  static const std::regex size(R"(^\s*(\d{1,9})\s*[xX]\s*(\d{1,9})\s*$)");
  std::smatch m;
  long long w = 0, h = 0;
  if (std::regex_match(text, m, size)) w = std::stoll(m[1]), h = std::stoll(m[2]);
  if (w < 1 || h < 1 || w > kMaxEyeDimension || h > kMaxEyeDimension)
    throw Error("--eye-size must be WxH between 1x1 and " + std::to_string(kMaxEyeDimension) + "x" +
                std::to_string(kMaxEyeDimension) + ", got '" + text + "'");
  rig.width = int(w), rig.height = int(h);
}

void validateOptions(const RenderOptions& o, const StereoRig& rig) {
  if (o.photonsX == 0 || o.photonsY == 0) throw Error("the number of photons must be positive");
  if (uint64_t(o.photonsX) * o.photonsY > (uint64_t(1) << 26))
    throw Error("too many photons: " + std::to_string(uint64_t(o.photonsX) * o.photonsY) + " (at most 8192x8192)");
  if (o.maxPhotonDepth < 1 || o.maxPhotonDepth > 64) throw Error("the photon depth must be between 1 and 64");
  const DensityParams& d = o.gather.density;
  if (!(d.radius > 0.0f) || !std::isfinite(d.radius)) throw Error("the search radius must be a positive finite number");
  if (d.estimator == Estimator::Knn && (d.k < 1 || d.k > kMaxKnn))
    throw Error("k must be between 1 and " + std::to_string(kMaxKnn));
  if (o.gather.samplesPerPixel < 1 || o.gather.samplesPerPixel > 4096)
    throw Error("samples per pixel must be between 1 and 4096");
  if (o.gather.maxSpecularDepth < 0 || o.gather.maxSpecularDepth > 64)
    throw Error("the specular depth must be between 0 and 64");
  if (rig.width < 1 || rig.height < 1 || rig.width > kMaxEyeDimension || rig.height > kMaxEyeDimension)
    throw Error("the eye size must be between 1x1 and " + std::to_string(kMaxEyeDimension) + "x" +
                std::to_string(kMaxEyeDimension) + ", got " + std::to_string(rig.width) + "x" + std::to_string(rig.height));
  if (!(rig.ipd >= 0.0f) || !std::isfinite(rig.ipd)) throw Error("the IPD must be a non-negative finite number");
  if ((o.kernel == DensityKernel::SharedMemory || o.kernel == DensityKernel::CellSorted) &&
      o.map != PhotonMapKind::HashGrid)
    throw Error(std::string("the ") + densityKernelName(o.kernel) + " kernel works on the hash grid, not the kd-tree");
  if (o.foveation.mask) {
    for (int e = 0; e < 2; ++e)
      for (float g : o.foveation.gaze[e])
        if (!(g >= 0.0f && g <= 1.0f)) throw Error("the gaze must lie in the image: coordinates between 0 and 1");
  }
  if (o.temporal.enabled) {
    const TaaParams& t = o.temporal.taa;
    if (!(t.blend > 0.0f && t.blend <= 1.0f)) throw Error("the TAA blend must be in (0, 1]");
    if (!(t.depthTolerance > 0.0f && t.depthTolerance < 1.0f))
      throw Error("the TAA depth tolerance must be in (0, 1)");
  }
  if (o.stereo != StereoMode::Separate && !(o.eyes[0] && o.eyes[1]))
    throw Error(std::string("stereo reuse (") + stereoModeName(o.stereo) + ") renders the right eye from the left: it needs both eyes");
}

}  // namespace pvr
