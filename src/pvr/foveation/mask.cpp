#include "pvr/foveation/mask.h"

#include <atomic>

#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>


#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>

#include "pvr/util/error.h"
#include "pvr/util/parallel_for.h"

namespace pvr {
namespace {

constexpr char kMagic[8] = {'P', 'V', 'R', 'M', 'A', 'S', 'K', '1'};
constexpr uint32_t kVersion = 1;
constexpr uint32_t kMaxVertices = 1u << 26;
constexpr double kDegPerRad = 180.0 / 3.14159265358979323846;

void checkParams(const MaskParams& p) {
  if (p.width < 1 || p.height < 1 || p.width > 8192 || p.height > 8192)
    throw Error("mask: the eye size must be between 1x1 and 8192x8192");
  if (!(p.tanPerPixel > 0.0f) || !std::isfinite(p.tanPerPixel)) throw Error("mask: the pixel size must be positive");
  const AcuityModel& a = p.acuity;
  if (!(a.mar0Deg > 0.0f && a.mar0Deg < 10.0f)) throw Error("mask: omega0 must be between 0 and 10 degrees");
  if (!(a.marSlope >= 0.0f && a.marSlope < 1.0f)) throw Error("mask: the MAR slope must be between 0 and 1");
  if (!(a.gazeMarginDeg >= 0.0f && a.gazeMarginDeg <= 90.0f))
    throw Error("mask: the gaze margin must be between 0 and 90 degrees");
  if (!(a.alpha > 0.0f) || !(a.e2Deg > 0.0f) || !(a.contrastThreshold0 > 0.0f && a.contrastThreshold0 < 1.0f))
    throw Error("mask: Geisler-Perry constants must be positive (CT0 below 1)");
}

// Little-endian scalar I/O (x86 and the GPU machines are little-endian).
template <class T>
void put(std::ofstream& out, const T& v) {
  out.write(reinterpret_cast<const char*>(&v), sizeof v);
}
template <class T>
T get(std::ifstream& in, const std::string& path) {
  T v;
  if (!in.read(reinterpret_cast<char*>(&v), sizeof v)) throw Error("mask file '" + path + "' is truncated");
  return v;
}

}  // namespace

MaskParams maskParamsForRig(const StereoRig& rig) {
  MaskParams params;
  params.width = rig.width, params.height = rig.height;
  for (const Fov& f : rig.fov)
    params.tanPerPixel = std::max({params.tanPerPixel, (std::tan(f.angleRight) - std::tan(f.angleLeft)) / float(rig.width),
                                   (std::tan(f.angleUp) - std::tan(f.angleDown)) / float(rig.height)});
  return params;
}

double eccentricityDeg(double radiusPixels, double tanPerPixel) {
  return std::atan(radiusPixels * tanPerPixel) * kDegPerRad;
}

double pixelPitchDeg(double radiusPixels, double tanPerPixel) {
  double t = radiusPixels * tanPerPixel;
  return tanPerPixel / (1.0 + t * t) * kDegPerRad;  // d(atan(r * tpp)) / dr
}

double sampleSpacingPixels(const MaskParams& p, double radiusPixels) {
  // AcuityModel::sampleSpacingDeg, in pixels: the acuity spacing, never finer than a pixel.
  double acuity = p.acuity.acuitySpacingDeg(float(eccentricityDeg(radiusPixels, p.tanPerPixel)));
  return std::max(1.0, acuity / pixelPitchDeg(radiusPixels, p.tanPerPixel));
}

uint64_t newMaskId() {
  static std::atomic<uint64_t> next{1};
  return next++;
}

FoveationMask generateFoveationMask(const MaskParams& params) {
  checkParams(params);
  FoveationMask mask;
  mask.params = params;
  // Full density: every pixel centre within the radius where the spacing first exceeds a pixel.
  int full = 0;
  while (full < 65536 && sampleSpacingPixels(params, full + 1) <= 1.0) ++full;
  mask.fullDensityRadius = full;
  for (int y = -full; y <= full; ++y)
    for (int x = -full; x <= full; ++x)
      if (x * x + y * y <= full * full) mask.offsets.push_back({float(x), float(y)});
  // Rings out to past the diagonal: the convex hull then holds the image for any gaze inside it.
  const double diagonal = std::hypot(double(params.width), double(params.height));
  double r = full + sampleSpacingPixels(params, full);
  const double goldenAngle = 2.39996322972865332;  // turns successive rings' phases apart
  for (int ring = 0;; ++ring) {
    double spacing = sampleSpacingPixels(params, r);
    int n = std::max(8, int(std::ceil(2.0 * 3.14159265358979323846 * r / spacing)));
    double phase = ring * goldenAngle;
    for (int i = 0; i < n; ++i) {
      double a = phase + 2.0 * 3.14159265358979323846 * i / n;
      mask.offsets.push_back({float(r * std::cos(a)), float(r * std::sin(a))});
    }
    if (r * std::cos(3.14159265358979323846 / n) > diagonal) break;  // the ring's inscribed circle
    r += spacing;
    if (mask.offsets.size() > kMaxVertices) throw Error("mask: too many samples");
  }

  using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
  using VertexBase = CGAL::Triangulation_vertex_base_with_info_2<uint32_t, Kernel>;
  using Tds = CGAL::Triangulation_data_structure_2<VertexBase>;
  using Delaunay = CGAL::Delaunay_triangulation_2<Kernel, Tds>;
  std::vector<std::pair<Kernel::Point_2, uint32_t>> points;
  points.reserve(mask.offsets.size());
  for (uint32_t i = 0; i < mask.offsets.size(); ++i)
    points.emplace_back(Kernel::Point_2(mask.offsets[i].x, mask.offsets[i].y), i);
  Delaunay delaunay(points.begin(), points.end());
  mask.triangles.reserve(delaunay.number_of_faces() * 3);
  for (auto face = delaunay.finite_faces_begin(); face != delaunay.finite_faces_end(); ++face)
    for (int k = 0; k < 3; ++k) mask.triangles.push_back(face->vertex(k)->info());
  mask.id = newMaskId();
  return mask;
}

void saveFoveationMask(const FoveationMask& mask, const std::string& path) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw Error("cannot write '" + path + "'");
  out.write(kMagic, sizeof kMagic);
  const MaskParams& p = mask.params;
  put(out, kVersion);
  put(out, int32_t(p.width));
  put(out, int32_t(p.height));
  put(out, p.tanPerPixel);
  put(out, int32_t(p.acuity.kind));
  for (float v : {p.acuity.mar0Deg, p.acuity.marSlope, p.acuity.alpha, p.acuity.e2Deg, p.acuity.contrastThreshold0,
                  p.acuity.gazeMarginDeg})
    put(out, v);
  put(out, int32_t(mask.fullDensityRadius));
  put(out, uint32_t(mask.offsets.size()));
  put(out, uint32_t(mask.triangleCount()));
  out.write(reinterpret_cast<const char*>(mask.offsets.data()), std::streamsize(mask.offsets.size() * sizeof(MaskPoint)));
  out.write(reinterpret_cast<const char*>(mask.triangles.data()), std::streamsize(mask.triangles.size() * sizeof(uint32_t)));
  if (!out) throw Error("cannot write '" + path + "'");
}

FoveationMask loadFoveationMask(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot open mask file '" + path + "': no such file or not readable");
  char magic[8];
  if (!in.read(magic, sizeof magic) || std::memcmp(magic, kMagic, sizeof magic) != 0)
    throw Error("'" + path + "' is not a photonvr mask file (make one with `photonvr mask`)");
  uint32_t version = get<uint32_t>(in, path);
  if (version != kVersion)
    throw Error("mask file '" + path + "' has version " + std::to_string(version) + ", this photonvr reads version " +
                std::to_string(kVersion));
  FoveationMask mask;
  MaskParams& p = mask.params;
  p.width = get<int32_t>(in, path);
  p.height = get<int32_t>(in, path);
  p.tanPerPixel = get<float>(in, path);
  int32_t kind = get<int32_t>(in, path);
  if (kind != int32_t(AcuityKind::LinearMar) && kind != int32_t(AcuityKind::GeislerPerry))
    throw Error("mask file '" + path + "' is corrupt: unknown acuity model");
  p.acuity.kind = AcuityKind(kind);
  for (float* v : {&p.acuity.mar0Deg, &p.acuity.marSlope, &p.acuity.alpha, &p.acuity.e2Deg,
                   &p.acuity.contrastThreshold0, &p.acuity.gazeMarginDeg})
    *v = get<float>(in, path);
  try {
    checkParams(p);
  } catch (const Error& e) {
    throw Error("mask file '" + path + "' is corrupt: " + e.what());
  }
  mask.fullDensityRadius = get<int32_t>(in, path);
  uint32_t vertices = get<uint32_t>(in, path), triangles = get<uint32_t>(in, path);
  if (vertices < 3 || vertices > kMaxVertices || triangles == 0 || triangles > 2 * kMaxVertices)
    throw Error("mask file '" + path + "' is corrupt: " + std::to_string(vertices) + " vertices, " +
                std::to_string(triangles) + " triangles");
  // The counts must match the bytes left before anything is allocated: a corrupt header must not
  // ask for gigabytes.
  const std::streamoff here = in.tellg();
  in.seekg(0, std::ios::end);
  const std::streamoff left = in.tellg() - here;
  in.seekg(here);
  const std::streamoff expected = std::streamoff(vertices) * std::streamoff(sizeof(MaskPoint)) +
                                  std::streamoff(triangles) * 3 * std::streamoff(sizeof(uint32_t));
  if (left < expected)
    throw Error("mask file '" + path + "' is truncated: its header claims " + std::to_string(vertices) + " vertices and " +
                std::to_string(triangles) + " triangles (" + std::to_string(expected) + " bytes), " +
                std::to_string(left) + " bytes follow");
  mask.offsets.resize(vertices);
  mask.triangles.resize(size_t(triangles) * 3);
  if (!in.read(reinterpret_cast<char*>(mask.offsets.data()), std::streamsize(vertices * sizeof(MaskPoint))) ||
      !in.read(reinterpret_cast<char*>(mask.triangles.data()), std::streamsize(mask.triangles.size() * sizeof(uint32_t))))
    throw Error("mask file '" + path + "' is truncated");
  if (in.peek() != std::char_traits<char>::eof()) throw Error("mask file '" + path + "' has trailing data");
  for (const MaskPoint& v : mask.offsets)
    if (!std::isfinite(v.x) || !std::isfinite(v.y)) throw Error("mask file '" + path + "' is corrupt: non-finite vertex");
  for (uint32_t i : mask.triangles)
    if (i >= vertices) throw Error("mask file '" + path + "' is corrupt: vertex index out of range");
  mask.id = newMaskId();
  return mask;
}

namespace {

void rasterizeMask(const FoveationMask& mask, int gazeX, int gazeY, const VertexValues& in, const RasterTarget& out) {
  // Each pixel centre belongs to one triangle: triangles write disjoint pixels, in parallel.
  parallelFor("foveated reconstruction", mask.triangleCount(), 512, [&](size_t begin, size_t end) {
    for (size_t t = begin; t < end; ++t)
      rasterizeTriangle(mask.offsets.data(), mask.triangles.data(), t, gazeX, gazeY, in, out);
  });
}

}  // namespace

Image reconstructFoveatedImage(const FoveationMask& mask, int gazeX, int gazeY, const std::vector<Vec3>& vertexColours) {
  if (vertexColours.size() != mask.offsets.size()) throw Error("reconstruction needs one colour per mask vertex");
  Image image(mask.params.width, mask.params.height);
  rasterizeMask(mask, gazeX, gazeY, {vertexColours.data()}, {image.pixels.data(), nullptr, nullptr, image.width, image.height});
  return image;
}

void reconstructFoveatedEye(const FoveationMask& mask, int gazeX, int gazeY, const std::vector<Vec3>& vertexColours,
                            const std::vector<float>& vertexInverseDepths, FoveatedImage& eye) {
  if (vertexColours.size() != mask.offsets.size() || vertexInverseDepths.size() != mask.offsets.size())
    throw Error("reconstruction needs one colour and one depth per mask vertex");
  const int w = mask.params.width, h = mask.params.height;
  eye.image = Image(w, h);
  eye.inverseDepth.assign(size_t(w) * h, 0.0f);
  eye.sampleSpacing.assign(size_t(w) * h, 1.0f);
  rasterizeMask(mask, gazeX, gazeY, {vertexColours.data(), vertexInverseDepths.data()},
                {eye.image.pixels.data(), eye.inverseDepth.data(), eye.sampleSpacing.data(), w, h});
}

void checkMaskFits(const FoveationMask& mask, int width, int height) {
  if (mask.params.width != width || mask.params.height != height)
    throw Error("the foveation mask is for " + std::to_string(mask.params.width) + "x" +
                std::to_string(mask.params.height) + " eyes, the render is " + std::to_string(width) + "x" +
                std::to_string(height) + " (make one with `photonvr mask --eye-size " + std::to_string(width) + "x" +
                std::to_string(height) + "`)");
}

std::vector<uint8_t> verticesInUse(const FoveationMask& mask, int gazeX, int gazeY) {
  std::vector<uint8_t> used(mask.offsets.size(), 0);
  for (size_t t = 0; t < mask.triangleCount(); ++t) {
    MaskPoint v[3];
    uint32_t index[3];
    placeTriangle(mask.offsets.data(), mask.triangles.data(), t, gazeX, gazeY, v, index);
    int x0, x1, y0, y1;
    if (triangleBounds(v, mask.params.width, mask.params.height, x0, x1, y0, y1))
      for (uint32_t i : index) used[i] = 1;
  }
  return used;
}

}  // namespace pvr
