// The microfacet BSDF (shading/bsdf.h): white furnace (energy <= 1, sampling agrees with the
// BSDF integrated by quadrature, a white metal keeps 1 with Kulla-Conty's lobe, the uncompensated
// losses stated), the GGX albedo table against quadrature, reciprocity, the chi-square
// test of sampled directions against the pdf, and the BSDF-weighted density estimate against
// exact direct light on a glossy floor.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "pvr/cpu/cpu_backend.h"
#include "pvr/photon/gather.h"
#include "pvr/shading/bsdf.h"
#include "pvr/shading/ggx_albedo_generator.h"

namespace pvr {
namespace {

struct Config {
  const char* name;
  float metallic, roughness, transmission, specularF0;
  bool inside;  ///< wo in the denser medium (transmission)
};

BsdfParams paramsOf(const Config& c) {
  BsdfParams b;
  b.normal = normalize(Vec3(0.2f, 1.0f, -0.1f));
  b.baseColor = {1, 1, 1};
  b.metallic = c.metallic;
  b.alpha = std::max(kMinGgxAlpha, c.roughness * c.roughness);
  b.transmission = c.transmission;
  b.specularF0 = c.specularF0;
  if (c.transmission > 0) {
    b.etaO = c.inside ? 1.5f : 1.0f;
    b.etaI = c.inside ? 1.0f : 1.5f;
  }
  return b;
}

Vec3 directionAt(const BsdfParams& b, float cosTheta, float phi) {
  float s = std::sqrt(std::max(0.0f, 1.0f - cosTheta * cosTheta));
  return normalize(Frame::fromNormal(b.normal).toWorld({s * std::cos(phi), s * std::sin(phi), cosTheta}));
}

// The integral of f(wi) |cos| over one side of the surface in polar coordinates about `axis` (the
// lobe's peak), with angles from it spaced as s^2 so that cells are finest where a sharp lobe is.
template <class F>
double sideIntegral(Vec3 normal, Vec3 axis, bool upper, const F& f) {
  const int nS = 16000, nPhi = 48;  // the lobe is near-symmetric about its axis: phi matters little
  Frame frame = Frame::fromNormal(axis);
  double sum = 0;
  for (int i = 0; i < nS; ++i) {
    double s = (i + 0.5) / nS, theta = kPi * s * s, dTheta = 2.0 * kPi * s / nS;
    for (int j = 0; j < nPhi; ++j) {
      double phi = 2.0 * kPi * (j + 0.5) / nPhi;
      Vec3 wi = normalize(frame.toWorld({float(std::sin(theta) * std::cos(phi)), float(std::sin(theta) * std::sin(phi)),
                                         float(std::cos(theta))}));
      float cosI = dot(normal, wi);
      if ((cosI > 0.0f) != upper) continue;
      sum += double(f(wi)) * std::fabs(cosI) * std::sin(theta) * dTheta * (2.0 * kPi / nPhi);
    }
  }
  return sum;
}
double sideIntegral(const BsdfParams& b, Vec3 wo, Vec3 axis, bool upper) {
  return sideIntegral(b.normal, axis, upper, [&](Vec3 wi) { return luminance(b.eval(wo, wi)); });
}

// The albedo by quadrature, independent of the sampling code: the reflection side about the
// mirror direction, the transmission side about the refracted one.
double albedoByQuadrature(const BsdfParams& b, Vec3 wo) {
  double albedo = sideIntegral(b, wo, reflect(-wo, b.normal), true);
  if (b.transmission > 0.0f) {
    float cosO = dot(wo, b.normal), eta = b.etaO / b.etaI, sin2T = eta * eta * (1.0f - cosO * cosO);
    Vec3 axis = sin2T < 1.0f ? normalize(-wo * eta + b.normal * (eta * cosO - std::sqrt(1.0f - sin2T))) : -b.normal;
    albedo += sideIntegral(b, wo, axis, false);
  }
  return albedo;
}

class BsdfFurnace : public ::testing::TestWithParam<Config> {};

// Energy: the mean sample weight (f |cos| / pdf) is the albedo; it is <= 1, agrees with the
// quadrature, and single scattering loses at most the stated amount.
TEST_P(BsdfFurnace, SamplingAgreesWithQuadratureAndConservesEnergy) {
  const Config c = GetParam();
  BsdfParams b = paramsOf(c);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  for (float cosO : {0.95f, 0.6f, 0.2f}) {
    Vec3 wo = directionAt(b, cosO, 0.7f);
    const int n = 400000;
    double sum = 0, sum2 = 0;
    for (int k = 0; k < n; ++k) {
      float uLobe = u01(rng), u1 = u01(rng), u2 = u01(rng);
      BsdfSample s = sampleBsdf(b, wo, uLobe, u1, u2);
      double w = s.valid() ? luminance(s.weight) : 0.0;
      ASSERT_TRUE(std::isfinite(w));
      sum += w, sum2 += w * w;
    }
    double mean = sum / n, sigma = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n);
    double quad = albedoByQuadrature(b, wo);
    std::printf("%-22s cos_o %.2f: albedo %.4f (sampling) %.4f (quadrature)\n", c.name, cosO, mean, quad);
    EXPECT_LE(mean, 1.0 + 4 * sigma + 1e-5) << c.name << " cos_o " << cosO;
    EXPECT_LE(quad, 1.005) << c.name << " cos_o " << cosO;
    EXPECT_NEAR(mean, quad, 4 * sigma + 0.01 * quad) << c.name << " cos_o " << cosO;
    // Kulla-Conty's lobe gives back what one microfacet bounce loses: a white metal reflects 1
    // (within the table's interpolation; mirror-sharp lobes, without the lobe, by their own single
// scattering) and nothing is lost by the Lambertian base. Not
    // compensated, with the stated bounds: a white plastic's base under a rough layer (the layer's
    // coupling assumes a smooth interface; at grazing angles, roughness 1 keeps 0.69), at most 10%
    // at roughness <= 0.3; and transmission: inside glass, total internal reflection sends most
    // light back into the reflection lobe, not compensated from that side: at roughness 1 down to 40%.
    if (c.transmission == 0.0f && c.metallic == 1.0f) EXPECT_NEAR(quad, 1.0, 0.005) << c.name << " cos_o " << cosO;
    double floor = c.roughness <= 0.3f ? 0.9 : c.inside ? 0.4 : 0.65;
    if (c.specularF0 == 0.0f && c.metallic == 0.0f && c.transmission == 0.0f) floor = 0.999;
    EXPECT_GE(quad, floor) << c.name << " cos_o " << cosO;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Materials, BsdfFurnace,
    ::testing::Values(Config{"lambertian limit", 0, 1, 0, 0, false}, Config{"metal r0.05", 1, 0.05f, 0, 0.04f, false},
                      Config{"metal r0.3", 1, 0.3f, 0, 0.04f, false}, Config{"metal r1", 1, 1, 0, 0.04f, false},
                      Config{"plastic r0.1", 0, 0.1f, 0, 0.04f, false}, Config{"plastic r0.6", 0, 0.6f, 0, 0.04f, false},
                      Config{"plastic r1", 0, 1, 0, 0.04f, false}, Config{"glass r0.1 outside", 0, 0.1f, 1, 0.04f, false},
                      Config{"glass r0.5 outside", 0, 0.5f, 1, 0.04f, false},
                      Config{"glass r0.1 inside", 0, 0.1f, 1, 0.04f, true},
                      Config{"glass r1 inside", 0, 1, 1, 0.04f, true}),
    [](const ::testing::TestParamInfo<Config>& info) {
      std::string s = info.param.name;
      for (char& ch : s)
        if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
      return s;
    });

// The albedo table of ggx_albedo.h is the generator's output.
TEST(GgxAlbedo, TableIsTheGeneratorsOutput) {
  const GgxAlbedoTable t = makeGgxAlbedoTable();
  ASSERT_EQ(t.albedo.size(), size_t(kGgxAlbedoSize * kGgxAlbedoSize));
  for (size_t k = 0; k < t.albedo.size(); ++k)
    ASSERT_NEAR(t.albedo[k], kGgxAlbedoTable[k], 2e-6f) << "ggx_albedo_table.inc is not makeGgxAlbedoTable() at " << k;
  for (int j = 0; j < kGgxAlbedoSize; ++j) ASSERT_NEAR(t.averageAlbedo[j], kGgxAverageAlbedoTable[j], 2e-6f) << j;
}

// The single-scattering albedo E(mu, alpha) = int D(h) G2 (o.h) / mu over the microfacet normals h
// whose reflection leaves above the horizon, by quadrature in h (theta = atan(alpha tan t), fine
// where a sharp lobe is): independent of the visible-normal sampling that made the table.
double albedoOfOneBounce(float mu, float alpha) {
  const Ggx ggx{alpha};
  const double cosO = mu, sinO = std::sqrt(1.0 - double(mu) * mu);
  const int nT = 2000, nPhi = 128;
  const double tMax = std::atan(std::tan(0.5 * kPi - 1e-6) / alpha);
  double sum = 0.0;
  for (int i = 0; i < nT; ++i) {
    const double t = (i + 0.5) * tMax / nT, x = std::tan(t);
    const double dTheta = alpha / (1.0 + double(alpha) * alpha * x * x) * (tMax / nT) / (std::cos(t) * std::cos(t));
    const double theta = std::atan(alpha * x), c = std::cos(theta), s = std::sin(theta);
    for (int j = 0; j < nPhi; ++j) {
      const double phi = 2.0 * kPi * (j + 0.5) / nPhi;
      const double oh = sinO * s * std::cos(phi) + cosO * c, iz = 2.0 * oh * c - cosO;
      if (!(oh > 0.0) || !(iz > 0.0)) continue;
      sum += double(ggx.D(float(c), float(s * s))) * ggx.G2(mu, float(iz)) * oh / cosO * s * dTheta * (2.0 * kPi / nPhi);
    }
  }
  return sum;
}

// GGX at alpha 1 has D = 1 / pi and Lambda(mu) = (1 / mu - 1) / 2, so a white metal seen head-on
// reflects exactly the integral of mu / (1 + mu) over 0..1 in one bounce: 1 - ln 2. The table has
// it, agrees with quadrature at its nodes (2e-4) and between them (bilinear: within 1% for
// mu >= 0.1), and its E_avg (of the interpolated rows) is the exact cosine-weighted mean within 0.2%.
TEST(GgxAlbedo, TableAgreesWithQuadratureAndOneMinusLnTwo) {
  EXPECT_NEAR(albedoOfOneBounce(1.0f, 1.0f), 1.0 - std::log(2.0), 2e-4);
  EXPECT_NEAR(ggxAlbedo(1.0f, 1.0f), 1.0 - std::log(2.0), 2e-4);
  for (int j : {3, 10, 20, 31})
    for (int i : {4, 12, 31}) {
      const float mu = ggxAlbedoNodeMu(i), alpha = ggxAlbedoNodeAlpha(j);
      EXPECT_NEAR(ggxAlbedo(mu, alpha), albedoOfOneBounce(mu, alpha), 2e-4) << "node mu " << mu << " alpha " << alpha;
    }
  for (float roughness : {0.17f, 0.45f, 0.83f})
    for (float mu : {0.1f, 0.37f, 0.71f}) {
      const float alpha = roughness * roughness;
      const double exact = albedoOfOneBounce(mu, alpha);
      EXPECT_NEAR(ggxAlbedo(mu, alpha), exact, 0.01 * exact) << "mu " << mu << " roughness " << roughness;
    }
  for (int j : {5, 15, 25, 31}) {
    const float alpha = ggxAlbedoNodeAlpha(j);
    EXPECT_NEAR(ggxAverageAlbedo(alpha), integrateGgxAverageAlbedo(alpha), 2e-3) << "alpha " << alpha;
  }
}

// With Kulla-Conty's lobe a white metal seen head-on at alpha 1 reflects 1 (not 1 - ln 2), by
// sampling too; a gold one reflects more than one bounce gives, and at most 1.
TEST(Bsdf, RoughMetalsKeepTheirEnergy) {
  BsdfParams b = paramsOf(Config{"metal r1", 1, 1, 0, 0.04f, false});
  EXPECT_NEAR(albedoByQuadrature(b, b.normal), 1.0, 2e-3);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  double sum = 0;
  const int n = 1000000;
  for (int k = 0; k < n; ++k) {
    float uLobe = u01(rng), u1 = u01(rng), u2 = u01(rng);
    BsdfSample s = sampleBsdf(b, b.normal, uLobe, u1, u2);
    if (s.valid()) sum += s.weight.x;
  }
  EXPECT_NEAR(sum / n, 1.0, 2e-3);
  b.baseColor = {1.0f, 0.78f, 0.34f};  // gold-like F0
  for (float cosO : {0.9f, 0.5f, 0.15f}) {
    const Vec3 wo = directionAt(b, cosO, 0.3f);
    const double one = sideIntegral(b.normal, reflect(-wo, b.normal), true, [&](Vec3 wi) {
      const Vec3 h = normalize(wo + wi);
      const Ggx ggx{b.alpha};
      const float cosI = dot(b.normal, wi), cosOut = dot(b.normal, wo);
      return luminance(b.reflectionFresnel(fmaxf(dot(wo, h), 0.0f))) * ggx.D(b.normal, h) * ggx.G2(cosOut, cosI) /
             (4.0f * cosOut * cosI);
    });
    const double all = albedoByQuadrature(b, wo);
    std::printf("gold r1 cos_o %.2f: one bounce %.4f, with Kulla-Conty %.4f\n", cosO, one, all);
    EXPECT_GT(all, one + 0.05) << cosO;
    EXPECT_LE(all, 1.0) << cosO;
  }
}

// Kulla-Conty's lobe fades in only where single scattering loses 0.5-1 % on average: below that
// its cosine-sampled weight, (1 - E(cos_i)) / (1 - E_avg), would reach thousands at grazing
// angles (fireflies in the eye paths, disks of light in the photon map). Sample weights of white
// metals from mirror-sharp to roughness 0.4, at grazing and steep views, stay below 50.
TEST(Bsdf, SharpMetalsSampleWithoutFireflies) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  double largest = 0;
  for (float roughness : {0.0f, 0.05f, 0.1f, 0.15f, 0.18f, 0.2f, 0.22f, 0.25f, 0.3f, 0.4f})
    for (float cosO : {0.01f, 0.05f, 0.2f, 0.7f}) {
      BsdfParams b = paramsOf(Config{"metal", 1, roughness, 0, 0.04f, false});
      const Vec3 wo = directionAt(b, cosO, 0.4f);
      for (int k = 0; k < 100000; ++k) {
        float uLobe = u01(rng), u1 = u01(rng), u2 = u01(rng);
        const BsdfSample sample = sampleBsdf(b, wo, uLobe, u1, u2);
        if (sample.valid()) largest = std::max(largest, double(luminance(sample.weight)));
      }
    }
  std::printf("largest sample weight of a white metal, roughness 0..0.4: %.2f\n", largest);
  EXPECT_LT(largest, 50.0);
}

// Extreme parameters (a layer reflecting everything, the sharpest lobe, grazing and total internal
// reflection) give finite values everywhere: one NaN photon blackens a whole disk of the image.
TEST(Bsdf, ExtremeParametersStayFinite) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  for (float f0 : {0.0f, 1.0f})
    for (float roughness : {0.0f, 1.0f})
      for (float metallic : {0.0f, 1.0f})
        for (float transmission : {0.0f, 1.0f})
          for (bool inside : {false, true}) {
            BsdfParams b = paramsOf(Config{"extreme", metallic, roughness, transmission, f0, inside});
            for (int k = 0; k < 2000; ++k) {
              Vec3 wo = directionAt(b, k == 0 ? 1e-6f : u01(rng), 2 * kPi * u01(rng));
              Vec3 wi = directionAt(b, 2 * u01(rng) - 1, 2 * kPi * u01(rng));
              ASSERT_TRUE(isFinite(b.eval(wo, wi))) << f0 << " " << roughness << " " << metallic << " " << transmission;
              ASSERT_TRUE(std::isfinite(b.pdf(wo, wi)));
              float uLobe = u01(rng), u1 = u01(rng), u2 = u01(rng);
              BsdfSample s = sampleBsdf(b, wo, uLobe, u1, u2);
              ASSERT_TRUE(isFinite(s.weight) && std::isfinite(s.pdf));
            }
          }
}

// Reflection is reciprocal; transmission (importance form) obeys f(o, i) / eta_i^2 = f(i, o) / eta_o^2.
TEST(Bsdf, ReciprocityOfReflectionAndTransmission) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  for (Config c : {Config{"metal", 1, 0.4f, 0, 0.04f, false}, Config{"plastic", 0, 0.5f, 0, 0.04f, false},
                   Config{"glass", 0, 0.5f, 1, 0.04f, false}}) {
    BsdfParams b = paramsOf(c);
    b.baseColor = {0.9f, 0.6f, 0.3f};
    for (int k = 0; k < 200; ++k) {
      Vec3 wo = directionAt(b, 0.05f + 0.95f * u01(rng), 2 * kPi * u01(rng));
      Vec3 wi = directionAt(b, 0.05f + 0.95f * u01(rng), 2 * kPi * u01(rng));
      Vec3 a = b.eval(wo, wi), r = b.eval(wi, wo);
      for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(a[ch], r[ch], 1e-4f * std::max(1.0f, a[ch])) << c.name;
      if (c.transmission == 0) continue;
      Vec3 below = directionAt(b, -(0.05f + 0.95f * u01(rng)), 2 * kPi * u01(rng));
      BsdfParams other = b;  // seen from inside: the normal on that side, the indices swapped
      other.normal = -b.normal;
      std::swap(other.etaO, other.etaI);
      float forward = b.eval(wo, below).x / (b.etaI * b.etaI);
      float backward = other.eval(below, wo).x / (other.etaI * other.etaI);
      EXPECT_NEAR(forward, backward, 1e-4f * std::max(1.0f, forward)) << "transmission";
    }
  }
}

// Upper quantile of the chi-square distribution (Wilson-Hilferty), accurate to ~1% for dof >= 10.
double chiSquareQuantile(int dof, double z) {
  double k = dof, h = 2.0 / (9.0 * k);
  return k * std::pow(1.0 - h + z * std::sqrt(h), 3.0);
}

// The histogram of sampled directions over (cos theta, phi) cells matches the pdf integrated
// over each cell; failed samples match the pdf's missing mass.
TEST(Bsdf, SampledDirectionsFollowThePdfChiSquare) {
  const int nTheta = 24, nPhi = 48, sub = 8, n = 1000000;
  for (Config c : {Config{"metal r0.2", 1, 0.2f, 0, 0.04f, false}, Config{"metal r0.7", 1, 0.7f, 0, 0.04f, false},
                   Config{"plastic r0.4", 0, 0.4f, 0, 0.04f, false}, Config{"glass r0.3", 0, 0.3f, 1, 0.04f, false},
                   Config{"glass r0.6 inside", 0, 0.6f, 1, 0.04f, true}}) {
    BsdfParams b = paramsOf(c);
    Vec3 wo = directionAt(b, 0.55f, 1.1f);
    Frame frame = Frame::fromNormal(b.normal);
    std::vector<double> observed(nTheta * nPhi + 1, 0.0), expected(nTheta * nPhi + 1, 0.0);
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    for (int k = 0; k < n; ++k) {
      float uLobe = u01(rng), u1 = u01(rng), u2 = u01(rng);
      BsdfSample s = sampleBsdf(b, wo, uLobe, u1, u2);
      if (!s.valid()) {
        observed[nTheta * nPhi] += 1;
        continue;
      }
      Vec3 l = frame.toLocal(s.wi);
      int i = std::clamp(int((l.z + 1.0f) * 0.5f * nTheta), 0, nTheta - 1);
      float phi = std::atan2(l.y, l.x);
      if (phi < 0) phi += 2 * kPi;
      int j = std::clamp(int(phi / (2 * kPi) * nPhi), 0, nPhi - 1);
      observed[i * nPhi + j] += 1;
    }
    double mass = 0;
    for (int i = 0; i < nTheta; ++i)
      for (int j = 0; j < nPhi; ++j) {
        double cell = 0;
        for (int a = 0; a < sub; ++a)
          for (int bb = 0; bb < sub; ++bb) {
            float cosTheta = -1.0f + 2.0f * (i + (a + 0.5f) / sub) / nTheta;
            float phi = 2 * kPi * (j + (bb + 0.5f) / sub) / nPhi;
            float s = std::sqrt(std::max(0.0f, 1.0f - cosTheta * cosTheta));
            cell += b.pdf(wo, normalize(frame.toWorld({s * std::cos(phi), s * std::sin(phi), cosTheta})));
          }
        cell *= (2.0 / nTheta) * (2 * kPi / nPhi) / (sub * sub);
        expected[i * nPhi + j] = cell * n;
        mass += cell;
      }
    EXPECT_LE(mass, 1.01) << c.name;
    expected[nTheta * nPhi] = std::max(0.0, 1.0 - mass) * n;
    // Cells expecting fewer than 5 samples are pooled (the usual rule).
    double chi2 = 0, pooledObs = 0, pooledExp = 0;
    int dof = -1;
    for (size_t k = 0; k < expected.size(); ++k) {
      if (expected[k] < 5) {
        pooledObs += observed[k], pooledExp += expected[k];
        continue;
      }
      chi2 += (observed[k] - expected[k]) * (observed[k] - expected[k]) / expected[k];
      ++dof;
    }
    if (pooledExp >= 5) {
      chi2 += (pooledObs - pooledExp) * (pooledObs - pooledExp) / pooledExp;
      ++dof;
    }
    double critical = chiSquareQuantile(dof, 3.72);  // significance 1e-4 per distribution
    std::printf("%-18s chi2 %.1f, %d degrees of freedom, critical %.1f, pdf mass %.4f\n", c.name, chi2, dof, critical, mass);
    EXPECT_LT(chi2, critical) << c.name;
  }
}

// A glossy (GGX) floor under a point light. Direct light gives f(wo, wi) E cos exactly; the photon
// map alone (every photon stored), weighting each photon by the BSDF for its direction, agrees.
TEST(Bsdf, GlossyFloorDirectLightAndPhotonEstimateAgree) {
  for (float metallic : {1.0f, 0.0f}) {
    Scene scene;
    Material glossy;
    glossy.type = MaterialType::Microfacet;
    glossy.albedo = {0.9f, 0.7f, 0.5f};
    glossy.metallic = metallic;
    glossy.roughness = 0.6f;
    uint32_t id = scene.addMaterial(glossy, "floor");
    scene.addMesh("floor", {{-4, 0, -4}, {4, 0, -4}, {4, 0, 4}, {-4, 0, 4}}, {}, {0, 2, 1, 0, 3, 2}, id);
    PunctualLight lamp;
    lamp.position = {0.4f, 1.2f, 0.0f};
    lamp.intensity = {20, 20, 20};
    scene.addPunctualLight(lamp, "lamp");
    scene.finalize();
    CpuBackend backend(scene);
    SceneView view = scene.view();
    PhotonTraceParams tp;
    tp.photonCount = 1u << 22;  // ~3000 photons in reach: 2% noise
    tp.storeDirect = true;
    tp.maxDepth = 1;
    const float radius = 0.08f;
    HashGrid grid = HashGrid::build(backend.tracePhotons(tp), radius);
    GatherParams full, photonsOnly;
    photonsOnly.mode = ShadingMode::PhotonMapOnly;
    photonsOnly.density.radius = full.density.radius = radius;
    for (Vec3 p : {Vec3(-0.2f, 0, 0.05f), Vec3(0.1f, 0, -0.1f), Vec3(-0.6f, 0, 0.3f)}) {
      Vec3 eye{-1.2f, 1.0f, 0.1f};
      Ray ray{eye, normalize(p - eye)};
      CounterRng rng(1, 0, 0);
      GatherPoint direct = traceToGatherPoint(view, backend.intersector(), full, ray, rng);
      // Analytic: f(wo, wi) I cos / r^2 with the BSDF at p.
      BsdfParams b;
      b.normal = {0, 1, 0};
      b.baseColor = glossy.albedo;
      b.metallic = metallic;
      b.alpha = 0.36f;
      Vec3 toLight = lamp.position - p;
      float r2 = lengthSquared(toLight);
      Vec3 wi = toLight / std::sqrt(r2);
      Vec3 expected = b.eval(-ray.dir, wi) * lamp.intensity * (wi.y / r2);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(direct.radiance[c], expected[c], 1e-4f * expected[c] + 1e-6f);
      CounterRng rng2(1, 0, 0);
      GatherPoint gp = traceToGatherPoint(view, backend.intersector(), photonsOnly, ray, rng2);
      ASSERT_NE(gp.lobes, 0u) << "roughness 0.6 is gathered with its BSDF";
      Vec3 estimate = finishGather(grid.view(), gp, photonsOnly.density);

      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(estimate[c], expected[c], 0.06f * expected[c]) << "metallic " << metallic << " channel " << c;
    }
  }
}

// A microfacet surface is view-dependent: stereo reuse never shares it between the eyes, while
// the same floor as a Lambertian one is shared.
TEST(Bsdf, MicrofacetFirstHitsAreNotReusedBetweenEyes) {
  for (MaterialType type : {MaterialType::Diffuse, MaterialType::Microfacet}) {
    Scene scene;
    Material m;
    m.type = type;
    uint32_t id = scene.addMaterial(m, "floor");
    scene.addMesh("floor", {{-4, 0, -4}, {4, 0, -4}, {4, 0, 4}, {-4, 0, 4}}, {}, {0, 2, 1, 0, 3, 2}, id);
    PunctualLight lamp;
    lamp.position = {0, 2, 0};
    scene.addPunctualLight(lamp, "lamp");
    scene.finalize();
    EmbreeIntersector intersector(scene);
    EyeCamera camera;
    camera.pose.position = {0, 1, 1};
    Ray ray{camera.pose.position, normalize(Vec3(0, -1, -1))};
    Hit hit;
    ASSERT_TRUE(intersector.intersect(ray, INFINITY, hit));
    EXPECT_EQ(surfaceRecordOf(scene.view(), camera, ray, hit).reusable(), type == MaterialType::Diffuse);
  }
}

}  // namespace
}  // namespace pvr

