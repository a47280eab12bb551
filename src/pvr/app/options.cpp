#include "pvr/app/options.h"

#include <regex>

namespace pvr {

StereoMode parseStereoMode(const std::string& text, const std::string& flag) {
  for (StereoMode m : {StereoMode::Separate, StereoMode::Scatter, StereoMode::Gather})
    if (text == stereoModeName(m)) return m;
  throw Error(flag + " must be separate, scatter or gather, got '" + text + "'");
}

void setEyeSize(StereoRig& rig, const std::string& text) {
  static const std::regex size(R"(^\s*(\d{1,9})\s*[xX]\s*(\d{1,9})\s*$)");
  std::smatch m;
  if (!std::regex_match(text, m, size))
    throw Error("--eye-size must be WxH (e.g. 1440x1600), got '" + text + "'");
  StereoRig sized = rig;
  sized.width = int(std::stoll(m[1])), sized.height = int(std::stoll(m[2]));
  try {
    validateRig(sized);
  } catch (const OptionError& e) {
    throw Error(describeForCli(e));
  }
  rig = sized;
}

const char* flagOf(RenderOption option) {
  switch (option) {
    case RenderOption::Photons: return "--photons";
    case RenderOption::PhotonDepth: return "--photon-depth";
    case RenderOption::Radius: return "--radius";
    case RenderOption::K: return "--k";
    case RenderOption::SamplesPerPixel: return "--spp";
    case RenderOption::SpecularDepth: return "--specular-depth";
    case RenderOption::ShadowRays: return "--shadow-rays";
    case RenderOption::EyeSize: return "--eye-size";
    case RenderOption::Ipd: return "--ipd";
    case RenderOption::Kernel: return "--kernel";
    case RenderOption::Gaze: return "--gaze";
    case RenderOption::TaaBlend: return "--taa-blend";
    case RenderOption::TaaDepthTolerance: return "--taa-depth-tolerance";
    case RenderOption::Stereo: return "--stereo";
    case RenderOption::DenoiseIterations: return "--denoise-iterations";
    case RenderOption::DenoiseDirectIterations: return "--denoise-direct-iterations";
    case RenderOption::PhotonBatches: return "--photon-batches";
    case RenderOption::DenoiseParameter: return "--denoise";
    case RenderOption::Density: return "--density";
    case RenderOption::CacheCell: return "--cache-cell";
  }
  return "--?";
}

std::string describeForCli(const OptionError& error) { return std::string(flagOf(error.option())) + ": " + error.what(); }

}  // namespace pvr
