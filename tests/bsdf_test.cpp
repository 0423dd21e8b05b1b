// The CPU reference's BSDFs, each on its own, in the style of pbrt-v4's bsdfs_test and Mitsuba's
// BSDF tests: sample, eval and pdf agree (a chi-square test of the sampled directions against the
// pdf, and every sample's weight and density against eval and pdf), eval is reciprocal, and the
// energy a BSDF reflects is at most what arrives (all of it where nothing is lost).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "cpu/bsdf.h"
#include "cpu/warp.h"
#include "shared/sampling.h"

namespace vkray::cpu {
namespace {

using glm::dvec3;

// ---- The chi-square distribution's upper tail: Q(dof / 2, x / 2) (Numerical Recipes' gammq) ----------

double upper_incomplete_gamma_q(double a, double x) {
  if (x <= 0) return 1;
  const double log_prefix = -x + a * std::log(x) - std::lgamma(a);
  if (x < a + 1) {  // the series for P, then Q = 1 - P
    double term = 1 / a, sum = term;
    for (int n = 1; n < 10000 && std::abs(term) > std::abs(sum) * 1e-15; ++n) sum += term *= x / (a + n);
    return 1 - sum * std::exp(log_prefix);
  }
  // Lentz's continued fraction for Q.
  double b = x + 1 - a, c = 1e300, d = 1 / b, h = d;
  for (int i = 1; i < 10000; ++i) {
    const double an = -i * (i - a);
    b += 2;
    d = an * d + b;
    if (std::abs(d) < 1e-300) d = 1e-300;
    c = b + an / c;
    if (std::abs(c) < 1e-300) c = 1e-300;
    d = 1 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1) < 1e-15) break;
  }
  return std::exp(log_prefix) * h;
}

TEST(BsdfTest, ChiSquareTailMatchesKnownValues) {
  // Q(k/2, x/2) for the chi-square distribution: P(X > 3.841) = 0.05 at 1 dof, P(X > 18.307) = 0.05 at 10.
  EXPECT_NEAR(upper_incomplete_gamma_q(0.5, 3.841 / 2), 0.05, 1e-4);
  EXPECT_NEAR(upper_incomplete_gamma_q(5.0, 18.307 / 2), 0.05, 1e-4);
  EXPECT_NEAR(upper_incomplete_gamma_q(50.0, 135.807 / 2), 0.01, 1e-4);  // 100 dof
}

// ---- The BSDFs under test -----------------------------------------------------------------------------

struct Case {
  std::string name;
  Material material;
  bool front = true;  // seen from the side the geometric normal faces (a dielectric's outside)
};

Material material_of(MaterialType type, glm::vec3 color) {
  Material m;
  m.type = type;
  m.albedo = color;
  return m;
}

Material conductor(glm::vec2 alpha, glm::vec3 eta = glm::vec3(0.0f), glm::vec3 k = glm::vec3(1.0f), glm::vec3 color = glm::vec3(1.0f)) {
  Material m = material_of(MaterialType::roughconductor, color);
  m.alpha = alpha;
  m.eta = eta;
  m.k = k;
  return m;
}

Material dielectric(glm::vec2 alpha, float ior) {
  Material m = material_of(MaterialType::roughdielectric, glm::vec3(1.0f));
  m.alpha = alpha;
  m.ior = ior;
  return m;
}

Material metallic_roughness(glm::vec3 base, float metallic, float roughness, float ior = 1.5f, float transmission = 0.0f) {
  Material m = material_of(MaterialType::metallic_roughness, base);
  m.metallic = metallic;
  m.roughness = roughness;
  m.ior = ior;
  m.transmission = transmission;
  return m;
}

// The relative index n_t / n_i a transmitted direction crosses: a dielectric's, seen from outside
// (front) or inside; 1 through a thin sheet, which has the same medium on both sides.
double crossed_index(const Bsdf& bsdf, bool front) {
  if (bsdf.type == MaterialType::metallic_roughness) return 1.0;
  return front ? bsdf.ior : 1 / bsdf.ior;
}

// Gold: Mitsuba 3's Au preset as its RGB variants reduce it (read back with mi.traverse).
const glm::vec3 kGoldEta(0.143036f, 0.375307f, 1.44205f), kGoldK(3.983f, 2.38556f, 1.60336f);

std::vector<Case> glossy_cases() {
  return {{"diffuse", material_of(MaterialType::diffuse, glm::vec3(0.8f, 0.5f, 0.2f))},
          {"conductor_alpha_0.05", conductor(glm::vec2(0.05f))},
          {"conductor_alpha_0.2", conductor(glm::vec2(0.2f))},
          {"conductor_alpha_0.5_gold", conductor(glm::vec2(0.5f), kGoldEta, kGoldK)},
          {"conductor_alpha_1", conductor(glm::vec2(1.0f))},
          {"conductor_anisotropic", conductor(glm::vec2(0.1f, 0.6f), kGoldEta, kGoldK, glm::vec3(0.9f, 0.8f, 0.7f))},
          {"dielectric_alpha_0.1_outside", dielectric(glm::vec2(0.1f), 1.5f)},
          {"dielectric_alpha_0.5_outside", dielectric(glm::vec2(0.5f), 1.5f)},
          {"dielectric_alpha_0.3_inside", dielectric(glm::vec2(0.3f), 1.5f), false},
          {"dielectric_anisotropic_inside", dielectric(glm::vec2(0.6f, 0.15f), 1.33f), false},
          {"gltf_dielectric", metallic_roughness(glm::vec3(0.8f, 0.3f, 0.2f), 0.0f, 0.5f)},
          {"gltf_metal", metallic_roughness(glm::vec3(0.95f, 0.75f, 0.3f), 1.0f, 0.3f)},
          {"gltf_half_metal_ior_1.33", metallic_roughness(glm::vec3(0.2f, 0.6f, 0.9f), 0.5f, 0.8f, 1.33f)},
          {"gltf_smooth_dielectric", metallic_roughness(glm::vec3(0.5f), 0.0f, 0.3f)},
          {"gltf_thin_transmission", metallic_roughness(glm::vec3(0.9f, 0.7f, 0.5f), 0.0f, 0.4f, 1.5f, 1.0f)},
          {"gltf_half_transmission_part_metal", metallic_roughness(glm::vec3(0.6f, 0.8f, 0.4f), 0.3f, 0.7f, 1.33f, 0.5f)}};
}

// A normal that is not an axis, so that the frame about it is exercised, and directions around it.
const dvec3 kNormal = glm::normalize(dvec3(0.3, -0.5, 0.8));

dvec3 direction_at(double cos_theta, double phi, const dvec3& n) {
  const double sin_theta = std::sqrt(std::max(0.0, 1 - cos_theta * cos_theta));
  return glm::normalize(from_tangent_space({sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta}, n));
}

// ---- sample against pdf ------------------------------------------------------------------------------

// Bins over the whole sphere about n, equal in theta and phi (so a lobe near the normal still spans
// several), the pdf integrated over each on a grid kSubdivisions times finer.
constexpr int kThetaBins = 24, kPhiBins = 48, kSubdivisions = 16;
constexpr int kSamples = 200000;

int bin_of(const dvec3& local) {
  const double theta = std::acos(std::clamp(local.z, -1.0, 1.0));
  const double phi = std::atan2(local.y, local.x) + (local.y < 0 ? 2 * kPi : 0);
  const int t = std::min(kThetaBins - 1, int(theta / kPi * kThetaBins));
  const int p = std::min(kPhiBins - 1, int(phi / (2 * kPi) * kPhiBins));
  return t * kPhiBins + p;
}

struct ChiSquare {
  double statistic = 0;
  int dof = 0;
  double p_value = 1;
};

// Sampled counts against the pdf integrated over each bin (the midpoint rule on a finer grid); the
// samples that failed against the mass the pdf leaves outside the sphere. Bins expecting fewer than 5
// are pooled, as the test requires.
ChiSquare chi_square(const Bsdf& bsdf, const dvec3& wo, bool front) {
  const int bins = kThetaBins * kPhiBins;
  std::vector<double> observed(size_t(bins) + 1, 0.0), expected(size_t(bins) + 1, 0.0);
  for (uint32_t i = 0; i < uint32_t(kSamples); ++i) {
    uint32_t stream = gpu::pcg_hash(i * 0x9e3779b9u + 17u);
    const BsdfSample b = sample_bsdf(bsdf, wo, kNormal, front, stream);
    const bool failed = b.weight == dvec3(0.0);
    observed[failed ? size_t(bins) : size_t(bin_of(to_tangent_space(b.dir, kNormal)))] += 1;
  }
  double total = 0;
  const double d_theta = kPi / (kThetaBins * kSubdivisions), d_phi = 2 * kPi / (kPhiBins * kSubdivisions);
  for (int t = 0; t < kThetaBins * kSubdivisions; ++t) {
    const double theta = (t + 0.5) * d_theta;
    const double solid_angle = std::sin(theta) * d_theta * d_phi;
    for (int p = 0; p < kPhiBins * kSubdivisions; ++p) {
      const double phi = (p + 0.5) * d_phi;
      const double mass = pdf_bsdf(bsdf, wo, direction_at(std::cos(theta), phi, kNormal), kNormal, front) * solid_angle;
      expected[size_t((t / kSubdivisions) * kPhiBins + p / kSubdivisions)] += mass * kSamples;
      total += mass;
    }
  }
  expected[size_t(bins)] = std::max(0.0, 1 - total) * kSamples;
  ChiSquare result;
  double pooled_observed = 0, pooled_expected = 0;
  for (size_t i = 0; i < observed.size(); ++i) {
    if (expected[i] < 5) {
      pooled_observed += observed[i];
      pooled_expected += expected[i];
      continue;
    }
    result.statistic += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
    ++result.dof;
  }
  if (pooled_expected >= 5) {
    result.statistic += (pooled_observed - pooled_expected) * (pooled_observed - pooled_expected) / pooled_expected;
    ++result.dof;
  } else if (pooled_observed > 50) {
    result.statistic = 1e30;  // many samples where the pdf says almost none
  }
  result.dof -= 1;  // the counts sum to kSamples
  result.p_value = upper_incomplete_gamma_q(result.dof / 2.0, result.statistic / 2);
  return result;
}

const double kViewCosines[] = {0.95, 0.6, 0.2};

TEST(BsdfTest, SampledDirectionsFollowThePdf) {
  const std::vector<Case> cases = glossy_cases();
  // A 1% significance level over all the tests together (Sidak's correction).
  const double level = 1 - std::pow(0.99, 1.0 / double(cases.size() * std::size(kViewCosines)));
  for (const Case& c : cases) {
    const Bsdf bsdf = bsdf_of(c.material, dvec3(c.material.albedo));
    for (const double cos_o : kViewCosines) {
      const ChiSquare chi = chi_square(bsdf, direction_at(cos_o, 1.0, kNormal), c.front);
      EXPECT_GT(chi.p_value, level) << c.name << " at cos_o " << cos_o << ": chi^2 " << chi.statistic << " over " << chi.dof
                                    << " degrees of freedom";
    }
  }
}

TEST(BsdfTest, EachSampleCarriesEvalOverPdf) {
  for (const Case& c : glossy_cases()) {
    const Bsdf bsdf = bsdf_of(c.material, dvec3(c.material.albedo));
    for (const double cos_o : kViewCosines) {
      const dvec3 wo = direction_at(cos_o, 2.0, kNormal);
      for (uint32_t i = 0; i < 2000; ++i) {
        uint32_t stream = gpu::pcg_hash(i + 5u);
        const BsdfSample b = sample_bsdf(bsdf, wo, kNormal, c.front, stream);
        if (b.weight == dvec3(0.0)) continue;
        const double pdf = pdf_bsdf(bsdf, wo, b.dir, kNormal, c.front);
        ASSERT_NEAR(b.pdf, pdf, 1e-6 * pdf) << c.name;
        const dvec3 expected = eval_bsdf(bsdf, wo, b.dir, kNormal, c.front) / pdf;
        for (int ch = 0; ch < 3; ++ch) ASSERT_NEAR(b.weight[ch], expected[ch], 1e-6 * std::max(1.0, expected[ch])) << c.name;
      }
    }
  }
}

// ---- Reciprocity: f(wo, wi) = f(wi, wo), and across a dielectric f(wo, wi) / n_o^2 = f(wi, wo) / n_i^2 ----
// (n_o the index on wo's side, n_i on wi's).

TEST(BsdfTest, EvalIsReciprocal) {
  for (const Case& c : glossy_cases()) {
    const Bsdf bsdf = bsdf_of(c.material, dvec3(c.material.albedo));
    const bool transmits = bsdf.has(VKRAY_BSDF_TRANSMISSION);
    uint32_t stream = 99;
    for (int i = 0; i < 1000; ++i) {
      const dvec3 a = direction_at(gpu::next_random(stream), 2 * kPi * gpu::next_random(stream), kNormal);
      // b below the surface too where light passes through it.
      const double cos_b = transmits ? 2 * gpu::next_random(stream) - 1 : gpu::next_random(stream);
      const dvec3 b = direction_at(cos_b, 2 * kPi * gpu::next_random(stream), kNormal);
      const dvec3 f_ab = eval_bsdf(bsdf, a, b, kNormal, c.front) / std::abs(cos_b);
      dvec3 f_ba;
      if (cos_b > 0) {
        f_ba = eval_bsdf(bsdf, b, a, kNormal, c.front) / glm::dot(a, kNormal);
      } else {  // seen from the other side, whose index is the other
        const double eta = crossed_index(bsdf, c.front);  // n_b / n_a
        f_ba = eval_bsdf(bsdf, b, a, -kNormal, !c.front) / glm::dot(a, kNormal) / (eta * eta);
      }
      for (int ch = 0; ch < 3; ++ch) ASSERT_NEAR(f_ab[ch], f_ba[ch], 1e-9 * std::max(1.0, f_ab[ch])) << c.name << " cos_b " << cos_b;
    }
  }
}

TEST(BsdfTest, AnAnisotropicLobeRunsOnWithoutASeam) {
  // Two normals a hair apart, on either side of n.z = 0: the lobe barely changes. (A frame built
  // from the normal alone flips there, exchanging alpha_u and alpha_v: eval jumped twentyfold.)
  const Bsdf brushed = bsdf_of(conductor(glm::vec2(0.05f, 0.6f)), dvec3(1.0));
  const dvec3 middle = glm::normalize(dvec3(1, 1, 0));
  const dvec3 wo = glm::normalize(middle + dvec3(0, 0, 0.3)), wi = glm::normalize(middle + 0.4 * dvec3(-0.7071, 0.7071, 0.0));
  const dvec3 above = eval_bsdf(brushed, wo, wi, glm::normalize(middle + dvec3(0, 0, 1e-4)), true);
  const dvec3 below = eval_bsdf(brushed, wo, wi, glm::normalize(middle - dvec3(0, 0, 1e-4)), true);
  EXPECT_GT(above.x, 0.01);
  EXPECT_NEAR(below.x / above.x, 1.0, 0.01);
}

// ---- Energy -------------------------------------------------------------------------------------------

// The directional albedo, the integral of f cos over wi, two ways: the mean sample weight, and eval
// over directions uniform on the sphere; with the standard error of each. What passes through a
// dielectric counts by its power, its radiance times eta^2, the square of the relative index it crossed.
struct Albedo {
  dvec3 sampled{0.0}, sampled_error{0.0};
  dvec3 uniform{0.0}, uniform_error{0.0};
};

Albedo directional_albedo(const Bsdf& bsdf, const dvec3& wo, int samples, bool front = true) {
  const double eta = crossed_index(bsdf, front);
  Albedo a;
  dvec3 sum(0.0), sum2(0.0), usum(0.0), usum2(0.0);
  for (uint32_t i = 0; i < uint32_t(samples); ++i) {
    uint32_t stream = gpu::pcg_hash(i * 3u + 1u);
    const BsdfSample b = sample_bsdf(bsdf, wo, kNormal, front, stream);
    const dvec3 power = b.weight * (b.transmitted ? b.eta * b.eta : 1.0);
    sum += power;
    sum2 += power * power;
    const dvec3 w = uniform_sphere(gpu::next_random(stream), gpu::next_random(stream));
    const dvec3 u = eval_bsdf(bsdf, wo, w, kNormal, front) * (4 * kPi) * (glm::dot(w, kNormal) < 0 ? eta * eta : 1.0);
    usum += u;
    usum2 += u * u;
  }
  const double n = samples;
  a.sampled = sum / n;
  a.sampled_error = glm::sqrt(glm::max(dvec3(0.0), sum2 / n - a.sampled * a.sampled) / n);
  a.uniform = usum / n;
  a.uniform_error = glm::sqrt(glm::max(dvec3(0.0), usum2 / n - a.uniform * a.uniform) / n);
  return a;
}

TEST(BsdfTest, ReflectsAtMostWhatArrivesAndAllOfItWhereNothingIsLost) {
  for (const Case& c : glossy_cases()) {
    const Bsdf bsdf = bsdf_of(c.material, dvec3(c.material.albedo));
    for (const double cos_o : kViewCosines) {
      const Albedo a = directional_albedo(bsdf, direction_at(cos_o, 0.5, kNormal), 200000, c.front);
      for (int ch = 0; ch < 3; ++ch) {
        EXPECT_LE(a.sampled[ch], 1 + 4 * a.sampled_error[ch]) << c.name << " cos_o " << cos_o;
        // The two estimates of one integral agree (importance sampling hides no lobe eval has).
        const double error = std::hypot(a.sampled_error[ch], a.uniform_error[ch]);
        EXPECT_NEAR(a.sampled[ch], a.uniform[ch], 5 * error + 1e-3) << c.name << " cos_o " << cos_o;
      }
    }
  }
  // A Lambertian surface reflects its albedo exactly, every sample.
  const Bsdf white = bsdf_of(material_of(MaterialType::diffuse, glm::vec3(1.0f)), dvec3(1.0));
  const Albedo a = directional_albedo(white, direction_at(0.3, 0.0, kNormal), 1000);
  EXPECT_EQ(a.sampled, dvec3(1.0));
  // A smooth conductor with F = 1 seen from above loses next to nothing to masking; a rough one,
  // seen at a grazing angle, loses a part (single scattering, as Mitsuba's).
  const Albedo smooth = directional_albedo(bsdf_of(conductor(glm::vec2(0.01f)), dvec3(1.0)), direction_at(0.9, 0.0, kNormal), 20000);
  EXPECT_NEAR(smooth.sampled.x, 1.0, 1e-3);
  const Albedo rough = directional_albedo(bsdf_of(conductor(glm::vec2(1.0f)), dvec3(1.0)), direction_at(0.2, 0.0, kNormal), 200000);
  EXPECT_LT(rough.sampled.x, 0.9);
  EXPECT_GT(rough.sampled.x, 0.3);
  // A smooth dielectric keeps the power, reflected and passed on, from either side; one of index 1
  // is no surface: all of the light goes straight on.
  for (const bool front : {true, false}) {
    const Albedo clear = directional_albedo(bsdf_of(dielectric(glm::vec2(0.01f), 1.5f), dvec3(1.0)), direction_at(0.9, 0.0, kNormal),
                                            20000, front);
    EXPECT_NEAR(clear.sampled.x, 1.0, 2e-3) << (front ? "outside" : "inside");
  }
  const Bsdf matched = bsdf_of(dielectric(glm::vec2(0.5f), 1.0f), dvec3(1.0));
  const dvec3 wo = direction_at(0.3, 0.0, kNormal);
  uint32_t stream = 7;
  const BsdfSample through = sample_bsdf(matched, wo, kNormal, true, stream);
  EXPECT_TRUE(through.delta && through.transmitted);
  EXPECT_EQ(through.dir, -wo);
  EXPECT_EQ(through.weight, dvec3(1.0));
  EXPECT_EQ(stream, gpu::pcg_hash(0) * 0 + [] { uint32_t s = 7; for (int i = 0; i < 3; ++i) gpu::next_random(s); return s; }());
}

TEST(BsdfTest, AThinTransmittingSheetPassesWhatItDoesNotReflect) {
  // glTF's roughness 0 with transmission 1: Schlick's F reflected, the rest through the sheet
  // straight on (no bending: it has no inside), tinted by the base colour.
  const glm::vec3 base(0.9f, 0.5f, 0.2f);
  const Bsdf tinted = bsdf_of(metallic_roughness(base, 0.0f, 0.0f, 1.5f, 1.0f), dvec3(base));
  for (const double cos_o : {0.9, 0.5, 0.2}) {
    const dvec3 wo = direction_at(cos_o, 0.7, kNormal);
    const double f = 0.04 + 0.96 * std::pow(1 - cos_o, 5);
    const Albedo a = directional_albedo(tinted, wo, 20000);
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(a.sampled[ch], f + (1 - f) * base[ch], 2e-3) << "cos_o " << cos_o << " channel " << ch;
    // (GGX's long tails turn a few a little even at alpha 1e-4: 2% by more than 7 alpha.)
    int through = 0, straight = 0;
    for (uint32_t i = 0; i < 4000; ++i) {
      uint32_t stream = gpu::pcg_hash(i);
      const BsdfSample b = sample_bsdf(tinted, wo, kNormal, true, stream);
      if (!b.transmitted) continue;
      ++through;
      straight += glm::dot(b.dir, -wo) > 1 - 1e-6;
      EXPECT_GT(glm::dot(b.dir, -wo), 1 - 1e-2);
      EXPECT_EQ(b.eta, 1.0);
    }
    EXPECT_GT(through, 2000);
    EXPECT_GT(straight, 0.95 * through);
  }
  // Rough and white, what it reflects and passes together is what a white rough conductor with F = 1
  // of the same GGX alpha reflects: each microfacet sends F one way and 1 - F the other, and both
  // lobes lose the same to masking.
  const Bsdf sheet = bsdf_of(metallic_roughness(glm::vec3(1.0f), 0.0f, 0.7f, 1.5f, 1.0f), dvec3(1.0));
  const Bsdf metal = bsdf_of(conductor(glm::vec2(0.49f)), dvec3(1.0));
  for (const double cos_o : {0.9, 0.3}) {
    const Albedo a = directional_albedo(sheet, direction_at(cos_o, 0.2, kNormal), 200000);
    const Albedo b = directional_albedo(metal, direction_at(cos_o, 0.2, kNormal), 200000);
    EXPECT_NEAR(a.sampled.x, b.sampled.x, 5 * std::hypot(a.sampled_error.x, b.sampled_error.x) + 1e-3) << "cos_o " << cos_o;
    EXPECT_LT(a.sampled.x, 1.0);
  }
}

// ---- The delta BSDFs -----------------------------------------------------------------------------------

TEST(BsdfTest, AMirrorReflectsAboutTheNormal) {
  const Bsdf mirror = bsdf_of(material_of(MaterialType::mirror, glm::vec3(0.9f)), dvec3(0.9));
  const dvec3 wo = direction_at(0.4, 1.0, kNormal);
  uint32_t stream = 1;
  const BsdfSample b = sample_bsdf(mirror, wo, kNormal, true, stream);
  EXPECT_TRUE(b.delta);
  EXPECT_NEAR(glm::length(b.dir + wo - 2 * glm::dot(wo, kNormal) * kNormal), 0.0, 1e-12);
  EXPECT_EQ(b.weight, dvec3(0.9));
  EXPECT_EQ(stream, 1u);  // no number drawn
  EXPECT_EQ(eval_bsdf(mirror, wo, b.dir, kNormal, true), dvec3(0.0));
  EXPECT_EQ(pdf_bsdf(mirror, wo, b.dir, kNormal, true), 0.0);
}

TEST(BsdfTest, GlassReflectsWithTheFresnelProbabilityAndKeepsThePower) {
  const Bsdf glass = bsdf_of(material_of(MaterialType::glass, glm::vec3(0.0f)), dvec3(0.0));
  for (const bool front : {true, false}) {
    const double cos_i = 0.5, eta = front ? 1.5 : 1 / 1.5;
    double cos_t;
    const double f = fresnel_dielectric(cos_i, eta, cos_t);
    const dvec3 wo = direction_at(cos_i, 0.3, kNormal);
    int reflected = 0;
    const int n = 100000;
    for (uint32_t i = 0; i < uint32_t(n); ++i) {
      uint32_t stream = gpu::pcg_hash(i);
      const BsdfSample b = sample_bsdf(glass, wo, kNormal, front, stream);
      ASSERT_TRUE(b.delta);
      if (!b.transmitted) {
        ++reflected;
        EXPECT_EQ(b.weight, dvec3(1.0));
      } else {
        // Radiance scales by 1 / eta^2; the power it carries (times eta^2) is kept.
        EXPECT_NEAR(b.weight.x * eta * eta, 1.0, 1e-12);
        EXPECT_NEAR(std::sqrt(1 - glm::dot(b.dir, kNormal) * glm::dot(b.dir, kNormal)) * eta,
                    std::sqrt(1 - cos_i * cos_i), 1e-9);  // Snell's law
      }
    }
    EXPECT_NEAR(double(reflected) / n, f, 4 * std::sqrt(f * (1 - f) / n)) << (front ? "outside" : "inside");
  }
}

// ---- Fresnel --------------------------------------------------------------------------------------------

TEST(BsdfTest, ConductorFresnelMatchesKnownValues) {
  // eta 0, k 1 (Mitsuba's material "none"): everything is reflected, at every angle.
  for (const double c : {0.0, 0.3, 1.0}) EXPECT_NEAR(fresnel_conductor(c, dvec3(0.0), dvec3(1.0)).x, 1.0, 1e-12);
  // At normal incidence, ((eta - 1)^2 + k^2) / ((eta + 1)^2 + k^2).
  const dvec3 eta(0.2, 1.0, 2.0), k(3.0, 2.0, 0.0);
  const dvec3 f = fresnel_conductor(1.0, eta, k);
  for (int ch = 0; ch < 3; ++ch) {
    const double expected = ((eta[ch] - 1) * (eta[ch] - 1) + k[ch] * k[ch]) / ((eta[ch] + 1) * (eta[ch] + 1) + k[ch] * k[ch]);
    EXPECT_NEAR(f[ch], expected, 1e-12);
  }
  // With k = 0 it is the dielectric's.
  double cos_t;
  EXPECT_NEAR(fresnel_conductor(0.4, dvec3(1.5), dvec3(0.0)).x, fresnel_dielectric(0.4, 1.5, cos_t), 1e-12);
  // Grazing: everything.
  EXPECT_NEAR(fresnel_conductor(0.0, kGoldEta, kGoldK).y, 1.0, 1e-12);
}

TEST(BsdfTest, GgxNormalsIntegrateToTheProjectedArea) {
  // The microfacet normals' projected area is the surface's: the integral of D(m) cos(theta_m) is 1.
  for (const glm::dvec2 alpha : {glm::dvec2(0.1), glm::dvec2(0.5), glm::dvec2(1.0), glm::dvec2(0.2, 0.7)}) {
    double sum = 0;
    const int n = 2000;
    for (int t = 0; t < n; ++t) {
      const double cos_theta = (t + 0.5) / n;
      for (int p = 0; p < 64; ++p) {
        const double phi = (p + 0.5) * 2 * kPi / 64, s = std::sqrt(1 - cos_theta * cos_theta);
        sum += ggx_density({s * std::cos(phi), s * std::sin(phi), cos_theta}, alpha) * cos_theta * (1.0 / n) * (2 * kPi / 64);
      }
    }
    EXPECT_NEAR(sum, 1.0, 2e-3) << alpha.x << ", " << alpha.y;
  }
}

}  // namespace
}  // namespace vkray::cpu
