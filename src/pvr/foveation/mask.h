#pragma once
// The sampling mask of foveated rendering: sample positions whose density follows the eye's
// acuity around the gaze, and their Delaunay triangulation, made once in preprocessing
// (`photonvr mask`), saved to a file and loaded at start. Positions are offsets in pixels from
// the gaze pixel's centre; rendering moves the mask with the gaze by whole pixels, so the dense
// centre stays on pixel centres.
#include <string>
#include <vector>

#include "pvr/camera/stereo_rig.h"
#include "pvr/foveation/acuity.h"
#include "pvr/foveation/reconstruct.h"
#include "pvr/image/image.h"

namespace pvr {

struct MaskParams {
  int width = 1440, height = 1600;  ///< the eye's image
  float tanPerPixel = 0.0f;         ///< image-plane size of a pixel at the optical centre (tan units)
  AcuityModel acuity;
};

// Parameters (default acuity) for a headset rig: its eye size, and the coarser of the two eyes'
// pixels at the optical centre, so that the mask never has fewer samples than either eye needs.
MaskParams maskParamsForRig(const StereoRig& rig);

struct FoveationMask {
  MaskParams params;
  std::vector<MaskPoint> offsets;   ///< pixels, relative to the gaze pixel's centre
  std::vector<uint32_t> triangles;  ///< 3 vertex indices per triangle (Delaunay)
  int fullDensityRadius = 0;        ///< pixels: every pixel centre within it is a vertex
  /// Identifies the content: each mask made or loaded gets a new one (copies keep it). Backends
  /// that upload a mask once key their copy on it; change the content, give it a new one
  /// (newMaskId()).
  uint64_t id = 0;

  size_t triangleCount() const { return triangles.size() / 3; }
};

// A process-wide unique mask id.
uint64_t newMaskId();

// Eccentricity (degrees) of a point `radiusPixels` from the gaze, and the angular size (degrees)
// of a pixel there, along the radius, for an image plane with `tanPerPixel`.
double eccentricityDeg(double radiusPixels, double tanPerPixel);
double pixelPitchDeg(double radiusPixels, double tanPerPixel);
// Sample spacing in pixels at `radiusPixels` from the gaze: the acuity spacing, never below one pixel.
double sampleSpacingPixels(const MaskParams& params, double radiusPixels);

// Samples the mask (every pixel centre out to the radius where the spacing exceeds one pixel,
// then rings of growing spacing out past the image's diagonal, so that the mask covers the image
// for any gaze inside it) and triangulates it with CGAL's exact-predicate Delaunay triangulation.
// Throws pvr::Error for parameters out of range.
FoveationMask generateFoveationMask(const MaskParams& params);

// Binary file (little-endian, magic "PVRMASK1"). Throws pvr::Error naming the file on any
// failure: missing, truncated, wrong magic or version, indices out of range, non-finite values.
void saveFoveationMask(const FoveationMask& mask, const std::string& path);
FoveationMask loadFoveationMask(const std::string& path);

// Reconstructs an image from one colour per mask vertex, the mask placed with its origin at the
// centre of pixel (gazeX, gazeY). Pixels no triangle covers stay black (none, if the gaze is
// inside the image).
Image reconstructFoveatedImage(const FoveationMask& mask, int gazeX, int gazeY, const std::vector<Vec3>& vertexColours);
// A foveated eye's frame: its image, per-pixel inverse depth (blended from the vertices') and
// the spacing of the samples each pixel was rebuilt from (what TAA reads).
struct FoveatedImage {
  Image image;
  std::vector<float> inverseDepth, sampleSpacing;
};
void reconstructFoveatedEye(const FoveationMask& mask, int gazeX, int gazeY, const std::vector<Vec3>& vertexColours,
                            const std::vector<float>& vertexInverseDepths, FoveatedImage& eye);

// Throws pvr::Error unless the mask was made for this eye size.
void checkMaskFits(const FoveationMask& mask, int width, int height);

// Vertices whose triangles overlap the image for this gaze (the only ones that need shading).
std::vector<uint8_t> verticesInUse(const FoveationMask& mask, int gazeX, int gazeY);

}  // namespace pvr
