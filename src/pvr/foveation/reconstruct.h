#pragma once
// Reconstruction of an eye's image from the colours of a foveation mask's vertices: the mask's
// triangles are rasterized and each pixel centre takes the barycentric blend of its triangle's
// vertex colours. Host+device: the CPU backend and a CUDA raster kernel share it.
//
// Every pixel centre inside the mask belongs to exactly one triangle: edge functions are
// evaluated the same way (endpoints in vertex-index order) by both triangles of a shared edge, so
// their signs agree exactly, and a centre exactly on an edge or vertex goes to one side by the
// top-left rule.
#include "pvr/math/vec.h"

namespace pvr {

struct MaskPoint {
  float x = 0, y = 0;
};

// Twice the signed area of (a, b, p), in double: positive when p lies to the left of a -> b.
PVR_HOST_DEVICE inline double orient2d(MaskPoint a, MaskPoint b, double px, double py) {
  return (double(b.x) - double(a.x)) * (py - double(a.y)) - (double(b.y) - double(a.y)) * (px - double(a.x));
}

// The edge a -> b of a triangle, evaluated identically by both triangles that share it.
PVR_HOST_DEVICE inline double edgeFunction(MaskPoint a, uint32_t ia, MaskPoint b, uint32_t ib, double px, double py) {
  return ia < ib ? orient2d(a, b, px, py) : -orient2d(b, a, px, py);
}

// Ties on an edge belong to the triangle for which the edge runs "upwards" (or leftwards when
// horizontal): of the two directions of a shared edge exactly one qualifies.
PVR_HOST_DEVICE inline bool ownsEdgeTie(MaskPoint a, MaskPoint b) {
  float dx = b.x - a.x, dy = b.y - a.y;
  return dy > 0.0f || (dy == 0.0f && dx < 0.0f);
}

// Barycentric weights of (px, py) in the triangle (v, index), or false if the point is not
// covered by it. The triangle may have either orientation; degenerate ones cover nothing.
PVR_HOST_DEVICE inline bool coveredBy(const MaskPoint v[3], const uint32_t index[3], double px, double py,
                                      double weight[3]) {
  int i1 = 1, i2 = 2;
  double area = orient2d(v[0], v[1], double(v[2].x), double(v[2].y));
  if (area == 0.0) return false;
  if (area < 0.0) i1 = 2, i2 = 1, area = -area;  // make the triangle counter-clockwise
  const int order[3] = {0, i1, i2};
  double w[3];
  for (int e = 0; e < 3; ++e) {
    int a = order[e], b = order[(e + 1) % 3];
    double f = edgeFunction(v[a], index[a], v[b], index[b], px, py);
    if (f < 0.0 || (f == 0.0 && !ownsEdgeTie(v[a], v[b]))) return false;
    w[order[(e + 2) % 3]] = f;  // the edge's function weighs the opposite vertex
  }
  double sum = w[0] + w[1] + w[2];
  for (int k = 0; k < 3; ++k) weight[k] = w[k] / sum;
  return true;
}

// Triangle t of a mask (offsets, 3 indices per triangle) placed with its origin at the centre of
// pixel (gazeX, gazeY).
PVR_HOST_DEVICE inline void placeTriangle(const MaskPoint* offsets, const uint32_t* triangles, size_t t, int gazeX,
                                          int gazeY, MaskPoint v[3], uint32_t index[3]) {
  for (int k = 0; k < 3; ++k) {
    index[k] = triangles[3 * t + k];
    v[k] = {offsets[index[k]].x + float(gazeX) + 0.5f, offsets[index[k]].y + float(gazeY) + 0.5f};
  }
}

// Pixels [x0, x1) x [y0, y1) whose centres the triangle may cover, not clipped to any image (in
// floats: a loaded mask may hold offsets no int holds).
PVR_HOST_DEVICE inline void pixelBox(const MaskPoint v[3], float& x0, float& x1, float& y0, float& y1) {
  x0 = floorf(fminf(fminf(v[0].x, v[1].x), v[2].x) - 0.5f);
  y0 = floorf(fminf(fminf(v[0].y, v[1].y), v[2].y) - 0.5f);
  x1 = ceilf(fmaxf(fmaxf(v[0].x, v[1].x), v[2].x) - 0.5f) + 1.0f;
  y1 = ceilf(fmaxf(fmaxf(v[0].y, v[1].y), v[2].y) - 0.5f) + 1.0f;
}

// The pixel box clipped to the image; false if empty.
PVR_HOST_DEVICE inline bool triangleBounds(const MaskPoint v[3], int width, int height, int& x0, int& x1, int& y0,
                                           int& y1) {
  float fx0, fx1, fy0, fy1;
  pixelBox(v, fx0, fx1, fy0, fy1);
  if (!(fx1 > 0.0f && fy1 > 0.0f && fx0 < float(width) && fy0 < float(height))) return false;  // before int conversion
  x0 = int(fmaxf(0.0f, fx0));
  y0 = int(fmaxf(0.0f, fy0));
  x1 = int(fminf(float(width), fx1));
  y1 = int(fminf(float(height), fy1));
  return x0 < x1 && y0 < y1;
}

// The size of triangleBounds' box for a mask triangle placed at gaze pixel (gazeX, gazeY), not
// clipped to any image. The mask moves by whole pixels, so elsewhere the box is the same but for
// float rounding: at most a pixel wider or taller.
inline void triangleBoxSize(const MaskPoint* offsets, const uint32_t* triangles, size_t t, int gazeX, int gazeY,
                            int& boxWidth, int& boxHeight) {
  MaskPoint v[3];
  uint32_t index[3];
  placeTriangle(offsets, triangles, t, gazeX, gazeY, v, index);
  float x0, x1, y0, y1;
  pixelBox(v, x0, x1, y0, y1);
  const float limit = 1 << 24;  // a loaded mask may hold any finite offsets
  boxWidth = int(fminf(x1 - x0, limit));
  boxHeight = int(fminf(y1 - y0, limit));
}

// A mask's per-vertex values, and what the raster writes per pixel (null pointers: nothing).
struct VertexValues {
  const Vec3* colours = nullptr;
  const float* inverseDepths = nullptr;  ///< first-hit inverse depths, blended for TAA's reprojection
};
struct RasterTarget {
  Vec3* image = nullptr;
  float* inverseDepth = nullptr;   ///< inverse depth is affine in the image: exact on planes
  float* sampleSpacing = nullptr;  ///< the covering triangle's size, sqrt(2 area): 1 on the pixel grid
  int width = 0, height = 0;
};

PVR_HOST_DEVICE inline Vec3 blend(const double weight[3], Vec3 c0, Vec3 c1, Vec3 c2) {
  return {float(weight[0] * c0.x + weight[1] * c1.x + weight[2] * c2.x),
          float(weight[0] * c0.y + weight[1] * c1.y + weight[2] * c2.y),
          float(weight[0] * c0.z + weight[1] * c1.z + weight[2] * c2.z)};
}

// Writes the pixels whose centres triangle t covers; the caller may split the triangle's bounding
// box between `stride` workers (pixels first, first + stride, ...).
PVR_HOST_DEVICE inline void rasterizeTriangle(const MaskPoint* offsets, const uint32_t* triangles, size_t t,
                                              int gazeX, int gazeY, const VertexValues& in, const RasterTarget& out,
                                              int first = 0, int stride = 1) {
  MaskPoint v[3];
  uint32_t index[3];
  placeTriangle(offsets, triangles, t, gazeX, gazeY, v, index);
  int x0, x1, y0, y1;
  if (!triangleBounds(v, out.width, out.height, x0, x1, y0, y1)) return;
  const float spacing = float(sqrt(fabs(orient2d(v[0], v[1], double(v[2].x), double(v[2].y)))));
  const int boxWidth = x1 - x0, boxPixels = boxWidth * (y1 - y0);
  for (int k = first; k < boxPixels; k += stride) {
    int x = x0 + k % boxWidth, y = y0 + k / boxWidth;
    double weight[3];
    if (!coveredBy(v, index, x + 0.5, y + 0.5, weight)) continue;
    const size_t pixel = size_t(y) * out.width + x;
    out.image[pixel] = blend(weight, in.colours[index[0]], in.colours[index[1]], in.colours[index[2]]);
    if (out.inverseDepth)
      out.inverseDepth[pixel] = float(weight[0] * in.inverseDepths[index[0]] + weight[1] * in.inverseDepths[index[1]] +
                                      weight[2] * in.inverseDepths[index[2]]);
    if (out.sampleSpacing) out.sampleSpacing[pixel] = spacing;
  }
}

}  // namespace pvr
