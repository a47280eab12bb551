#pragma once
// The microfacet material's BSDF at one surface point (glTF 2.0's metallic-roughness model with
// KHR_materials_transmission), written once for eye paths, photon paths, direct light and the
// density estimate:
//
//   f = m F_metal(h.o) R + (1 - m) [ F_d(h.o) R + (1 - t) A(cos_o, cos_i) C / pi + t (1 - F_d(h.o)) C T ] + f_ms
//
// with m metallic, t transmission, C the base colour, R = D G2 / (4 |cos_o| |cos_i|) the GGX
// reflection lobe, T Walter et al.'s (2007) GGX transmission lobe, F_metal Schlick's with
// F0 = C, F_d Schlick's with the dielectric layer's F0 (from the ior, or OBJ's Ks) and F90 =
// min(1, 50 F0), using the transmitted angle inside the denser medium (and 1 beyond the critical
// angle), and A the diffuse base's coupling to the layer (diffuseScale). glTF's own
// (1 - F(h.o)) weighting of the base is not used: it gains up to 30% energy at grazing angles,
// and Ashikhmin-Shirley's coupling darkens rough plastics at grazing angles by half.
// The reflection lobe R includes Kulla and Conty's (2017) multiple-scattering lobe, which gives
// back the energy that one microfacet bounce loses (a white GGX metal at alpha 1 keeps only
// 1 - ln 2 = 0.307 of it head-on): f_ms = F_ms (1 - E(cos_o)) (1 - E(cos_i)) / (pi (1 - E_avg)),
// E the lobe's tabulated albedo (ggx_albedo.h), F_ms = F_avg^2 E_avg / (1 - F_avg (1 - E_avg))
// the light that leaves after further bounces with the cosine-averaged Fresnel F_avg. Reciprocal;
// a white metal reflects 1 at every roughness and angle. Transmission's loss is not compensated
// (rough glass loses energy; its table would need the ior as a third axis).
//
// Transmission is written in its importance-transport (photon) form, without the 1 / eta^2
// radiance factor, for eye and photon paths alike: the smooth Glass material does the same, and
// a path that enters and leaves a closed object sees the two factors cancel.
//
// Lobes: diffuse, reflection and transmission, chosen for sampling in proportion to their
// approximate albedo at wo and combined into one mixture pdf (one-sample MIS), so that a sample's
// weight f |cos| / pdf is unbiased for any subset of lobes.
#include "pvr/shading/ggx_albedo.h"
#include "pvr/shading/microfacet.h"
#include "pvr/util/sampling.h"

namespace pvr {

enum BsdfLobe : uint32_t { kLobeDiffuse = 1u, kLobeReflection = 2u, kLobeTransmission = 4u, kLobesAll = 7u };

// A reflection lobe this sharp is followed by sampling (as a mirror is) rather than gathered from
// the photon map, whose estimate of a narrow lobe is mostly noise.
constexpr float kGatheredMinAlpha = 0.09f;  // roughness 0.3

struct BsdfParams {
  Vec3 normal{0, 0, 1};  ///< shading normal, world space, on the side wo leaves from
  Vec3 baseColor{0.8f, 0.8f, 0.8f};
  float metallic = 0.0f;
  float alpha = 1.0f;        ///< GGX alpha = roughness^2, >= kMinGgxAlpha
  float transmission = 0.0f;
  float specularF0 = 0.04f;  ///< the dielectric layer's reflectance at normal incidence
  float etaO = 1.0f;         ///< index of refraction on wo's side
  float etaI = 1.0f;         ///< index on the other side (the ior, or 1 from inside)

  // The dielectric layer's Fresnel at a microfacet seen at cosO (> 0) from wo's side.
  PVR_HOST_DEVICE float dielectricFresnel(float cosO) const {
    float c = cosO;
    if (etaO > etaI) {  // inside the denser medium: Schlick at the transmitted angle
      float sin2T = (etaO / etaI) * (etaO / etaI) * fmaxf(0.0f, 1.0f - cosO * cosO);
      if (sin2T >= 1.0f) return 1.0f;
      c = sqrtf(1.0f - sin2T);
    }
    float f90 = fminf(1.0f, 50.0f * specularF0);
    return specularF0 + (f90 - specularF0) * schlickWeight(c);
  }

  // The diffuse base under the dielectric layer, relative to Lambertian: light enters and leaves
  // through the layer, (1 - F(cos_o)) (1 - F(cos_i)) / (1 - F_avg), with F the layer's Schlick
  // Fresnel and F_avg = F0 + (F90 - F0) / 21 its cosine-weighted mean. Reciprocal; under a smooth
  // layer reflected + diffused energy is exactly 1 for a white base; Lambertian as F0 -> 0.
  PVR_HOST_DEVICE float diffuseScale(float cosO, float cosI) const {
    float f90 = fminf(1.0f, 50.0f * specularF0);
    float fo = specularF0 + (f90 - specularF0) * schlickWeight(cosO);
    float fi = specularF0 + (f90 - specularF0) * schlickWeight(cosI);
    float average = specularF0 + (f90 - specularF0) * (1.0f / 21.0f);
    if (!(average < 1.0f)) return 0.0f;  // a layer that reflects everything leaves nothing below
    return (1.0f - fo) * (1.0f - fi) / (1.0f - average);
  }

  PVR_HOST_DEVICE Vec3 reflectionFresnel(float cosO) const {
    Vec3 metal = baseColor + (Vec3(1.0f) - baseColor) * schlickWeight(cosO);
    return metal * metallic + Vec3(dielectricFresnel(cosO) * (1.0f - metallic));
  }

  // Kulla-Conty's lobe (the header's f_ms) is colour * scale * (1 - E(cos_o)) (1 - E(cos_i)).
  // Sharp lobes lose little, and there the lobe would be a firefly source: its cosine-sampled
  // weight grows as (1 - E(cos_i)) / (1 - E_avg), about 2600 at the sharpest alpha and grazing
  // cos_i. So it fades in between 0.5 % and 1 % of average loss (roughness 0.2 to 0.25; weights
  // at most about 20), and sharper lobes keep their single-scattering albedo (>= 99.5 % on average).
  struct MultipleScattering {
    Vec3 color{0, 0, 0};  ///< F_ms: the metal's and the dielectric layer's, mixed by metallic (and the fade)
    float scale = 0.0f;   ///< 1 / (pi (1 - E_avg)); 0: none (a sharp lobe, or seen from inside)
  };
  PVR_HOST_DEVICE MultipleScattering multipleScattering() const {
    MultipleScattering ms;
    if (etaO > etaI) return ms;  // inside a dielectric: transmission's share is not compensated
    const float averageAlbedo = ggxAverageAlbedo(alpha);
    const float fade = fminf((1.0f - averageAlbedo - 0.005f) * 200.0f, 1.0f);
    if (!(fade > 0.0f)) return ms;
    ms.scale = kInvPi / (1.0f - averageAlbedo);
    auto furtherBounces = [&](float averageFresnel) {
      return averageFresnel * averageFresnel * averageAlbedo / (1.0f - averageFresnel * (1.0f - averageAlbedo));
    };
    // Schlick's Fresnel averaged over the cosine-weighted hemisphere: F0 + (F90 - F0) / 21.
    const Vec3 metal = baseColor + (Vec3(1.0f) - baseColor) * (1.0f / 21.0f);
    const float f90 = fminf(1.0f, 50.0f * specularF0);
    const float dielectric = specularF0 + (f90 - specularF0) * (1.0f / 21.0f);
    ms.color = (Vec3(furtherBounces(metal.x), furtherBounces(metal.y), furtherBounces(metal.z)) * metallic +
                Vec3(furtherBounces(dielectric) * (1.0f - metallic))) * fade;
    return ms;
  }

  // The reflection lobe's parts at wo (cosO > 0): single scattering (its approximate albedo, the
  // Fresnel reflectance) and the multiple-scattering lobe (its exact albedo, colour (1 - E(cos_o))).
  PVR_HOST_DEVICE void reflectionWeights(float cosO, float& single, float& multiple) const {
    single = luminance(reflectionFresnel(cosO));
    const MultipleScattering ms = multipleScattering();
    multiple = ms.scale > 0.0f ? fmaxf(luminance(ms.color), 0.0f) * (1.0f - ggxAlbedo(cosO, alpha)) : 0.0f;
  }
  // The multiple-scattering lobe's share of reflection samples at wo.
  PVR_HOST_DEVICE float multipleScatteringShare(float cosO) const {
    float single, multiple;
    reflectionWeights(cosO, single, multiple);
    return multiple > 0.0f ? multiple / (single + multiple) : 0.0f;
  }

  // Selection probabilities of the lobes in `lobes` at wo (local cosine cosO > 0); they sum to 1,
  // or are all 0 when none of them can reflect anything.
  PVR_HOST_DEVICE void lobeProbabilities(float cosO, uint32_t lobes, float p[3]) const {
    float fo = dielectricFresnel(cosO);
    float lum = fmaxf(luminance(baseColor), 0.0f);
    p[0] = (lobes & kLobeDiffuse) ? (1.0f - metallic) * (1.0f - transmission) * lum * (1.0f - fo) : 0.0f;
    p[1] = 0.0f;
    if (lobes & kLobeReflection) {
      float single, multiple;
      reflectionWeights(cosO, single, multiple);
      p[1] = single + multiple;
    }
    // Transmission keeps a share beyond the critical angle too: rough microfacets still refract.
    p[2] = (lobes & kLobeTransmission) ? (1.0f - metallic) * transmission * lum * fmaxf(1.0f - fo, 0.25f) : 0.0f;
    float sum = p[0] + p[1] + p[2];
    float inv = sum > 0.0f ? 1.0f / sum : 0.0f;
    for (int k = 0; k < 3; ++k) p[k] *= inv;
  }

  // The half vector of a transmission pair, on wo's side of the surface.
  PVR_HOST_DEVICE Vec3 transmissionHalfVector(Vec3 wo, Vec3 wi) const {
    Vec3 h = wo * etaO + wi * etaI;
    float len = length(h);
    if (!(len > 0.0f)) return {0, 0, 0};
    h = h * (1.0f / len);
    return dot(h, normal) < 0.0f ? -h : h;
  }

  // f(wo, wi) restricted to `lobes`; wo and wi unit, pointing away from the surface.
  PVR_HOST_DEVICE Vec3 eval(Vec3 wo, Vec3 wi, uint32_t lobes = kLobesAll) const {
    float cosO = dot(normal, wo), cosI = dot(normal, wi);
    if (!(cosO > 0.0f)) return {0, 0, 0};
    Ggx ggx{alpha};
    Vec3 f{0, 0, 0};
    if (cosI > 0.0f) {
      float diffuseWeight = (1.0f - metallic) * (1.0f - transmission);
      if ((lobes & kLobeDiffuse) && diffuseWeight > 0.0f) f += baseColor * (diffuseWeight * diffuseScale(cosO, cosI) * kInvPi);
      if (lobes & kLobeReflection) {
        Vec3 h = normalize(wo + wi);
        float c = fmaxf(dot(wo, h), 0.0f);
        f += reflectionFresnel(c) * (ggx.D(normal, h) * ggx.G2(cosO, cosI) / (4.0f * cosO * cosI));
        const MultipleScattering ms = multipleScattering();
        if (ms.scale > 0.0f)
          f += ms.color * (ms.scale * (1.0f - ggxAlbedo(cosO, alpha)) * (1.0f - ggxAlbedo(cosI, alpha)));
      }
    } else if (cosI < 0.0f && (lobes & kLobeTransmission) && transmission > 0.0f && metallic < 1.0f) {
      Vec3 h = transmissionHalfVector(wo, wi);
      float co = dot(wo, h), ci = dot(wi, h);
      if (!(co > 0.0f) || !(ci < 0.0f)) return f;  // a microfacet facing away from one of them
      float denom = etaI * ci + etaO * co;
      float t = (1.0f - metallic) * transmission * (1.0f - dielectricFresnel(co));
      f += baseColor * (t * ggx.D(normal, h) * ggx.G2(cosO, -cosI) * (-ci) * co * etaI * etaI /
                        (cosO * -cosI * denom * denom));
    }
    return f;
  }

  // The mixture pdf (per solid angle) of sampling wi from wo with `lobes`.
  PVR_HOST_DEVICE float pdf(Vec3 wo, Vec3 wi, uint32_t lobes = kLobesAll) const {
    float cosO = dot(normal, wo), cosI = dot(normal, wi);
    if (!(cosO > 0.0f)) return 0.0f;
    float p[3];
    lobeProbabilities(cosO, lobes, p);
    Frame frame = Frame::fromNormal(normal);
    Vec3 woL = frame.toLocal(wo);
    Ggx ggx{alpha};
    if (cosI > 0.0f) {
      float pdf = p[0] * cosI * kInvPi;
      if (p[1] > 0.0f) {
        Vec3 h = normalize(wo + wi);
        const float share = multipleScatteringShare(cosO);  // sampled by the cosine
        pdf += p[1] * ((1.0f - share) * ggx.visibleNormalPdf(woL, frame.toLocal(h)) / (4.0f * fmaxf(dot(wo, h), 1e-8f)) +
                       share * cosI * kInvPi);
      }
      return pdf;
    }
    if (!(cosI < 0.0f) || !(p[2] > 0.0f)) return 0.0f;
    Vec3 h = transmissionHalfVector(wo, wi);
    float co = dot(wo, h), ci = dot(wi, h);
    if (!(co > 0.0f) || !(ci < 0.0f)) return 0.0f;
    float denom = etaI * ci + etaO * co;
    return p[2] * ggx.visibleNormalPdf(woL, frame.toLocal(h)) * (-ci) * etaI * etaI / (denom * denom);
  }
};

struct BsdfSample {
  Vec3 wi{0, 0, 0};
  Vec3 weight{0, 0, 0};  ///< f |cos_i| / pdf, zero when the sample failed
  float pdf = 0.0f;
  PVR_HOST_DEVICE bool valid() const { return pdf > 0.0f && !isBlack(weight); }
};

// Samples wi from wo with the lobes in `lobes` (uLobe chooses the lobe, u1 and u2 the direction).
PVR_HOST_DEVICE inline BsdfSample sampleBsdf(const BsdfParams& b, Vec3 wo, float uLobe, float u1, float u2,
                                             uint32_t lobes = kLobesAll) {
  BsdfSample out;
  float cosO = dot(b.normal, wo);
  if (!(cosO > 0.0f)) return out;
  float p[3];
  b.lobeProbabilities(cosO, lobes, p);
  Frame frame = Frame::fromNormal(b.normal);
  Vec3 woL = frame.toLocal(wo);
  Vec3 wiL;
  if (uLobe < p[0]) {
    wiL = sampleCosineHemisphere(u1, u2);
  } else if (uLobe < p[0] + p[1]) {
    if (uLobe - p[0] < b.multipleScatteringShare(cosO) * p[1]) {  // the multiple-scattering lobe
      wiL = sampleCosineHemisphere(u1, u2);
    } else {
      Vec3 h = Ggx{b.alpha}.sampleVisibleNormal(woL, u1, u2);
      wiL = h * (2.0f * dot(woL, h)) - woL;
      if (!(wiL.z > 0.0f)) return out;
    }
  } else if (p[2] > 0.0f) {
    Vec3 h = Ggx{b.alpha}.sampleVisibleNormal(woL, u1, u2);
    float eta = b.etaO / b.etaI, cosH = dot(woL, h);
    float sin2T = eta * eta * fmaxf(0.0f, 1.0f - cosH * cosH);
    if (sin2T >= 1.0f) return out;  // total internal reflection at this microfacet: the reflection lobe's
    wiL = -woL * eta + h * (eta * cosH - sqrtf(1.0f - sin2T));
    if (!(wiL.z < 0.0f)) return out;
  } else {
    return out;
  }
  out.wi = normalize(frame.toWorld(wiL));
  out.pdf = b.pdf(wo, out.wi, lobes);
  if (!(out.pdf > 0.0f)) return BsdfSample();
  out.weight = b.eval(wo, out.wi, lobes) * (fabsf(dot(b.normal, out.wi)) / out.pdf);
  return out;
}

}  // namespace pvr
