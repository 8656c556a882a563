// libFuzzer target: the map's sampling structures on small adversarial maps (1 to 16 pixels a
// side; zeros, denormals, 1e30, NaN and negative texels; bilinear or not; MIS compensation;
// turned; or resampled from the image as a light probe), drawn from with every strategy at
// fuzzed (u1, u2) and normals, the zero normal included. What is checked: no read outside a table (AddressSanitizer); every draw and
// density finite, non-negative, with a unit direction; and a draw's density equal to pdf() of
// its direction, away from pixel edges and the poles.
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include "envmap/CollapsedMap.h"
#include "envmap/EnvironmentMap.h"
#include "envmap/LightProbe.h"
#include "fuzz/FuzzInput.h"

using namespace envgi;

namespace {

struct Bytes {
  const uint8_t* p;
  size_t n;
  uint8_t next() {
    if (n == 0) return 0;
    --n;
    return *p++;
  }
  // A number in [0, 1) on a 2^-24 lattice, so 0 and the largest float below 1 both occur.
  float unit() { return float((uint32_t(next()) << 16) | (uint32_t(next()) << 8) | next()) * 0x1p-24f; }
};

float texelValue(uint8_t b) {
  switch (b % 16) {
    case 0: return 0.f;
    case 1: return 1e-40f;  // denormal
    case 2: return 1e30f;
    case 3: return NAN;
    case 4: return -1.f;
    case 5: return INFINITY;
    default: return float(b) / 32.f;
  }
}

void check(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "fuzz_envmap: %s\n", what);
    std::abort();
  }
}

bool finite(Color c) { return std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z); }

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  Bytes in{data, size};
  int w = 1 + in.next() % 16, h = 1 + in.next() % 16;
  uint8_t flags = in.next();
  Image img(w, h);
  for (float& v : img.rgb) v = texelValue(in.next());
  EnvironmentMapOptions opts;
  opts.bilinear = flags & 1;
  opts.misCompensation = flags & 2;
  opts.adaptiveLeaves = 1 + in.next() % 64;
  if (flags & 4) opts.toWorld = rotate(Vec3f(0.3f, 1.f, -0.2f), 37.f);
  opts.scale = flags & 8 ? 1e-3f : 2.f;
  if (flags & 16) {
    // The map as a light probe's resampling: a square image converts, any other is refused.
    ProbeLayout layout = flags & 32 ? ProbeLayout::MirrorBall : (flags & 64 ? ProbeLayout::Cross : ProbeLayout::Angular);
    ProbeConversion c{2 * (1 + in.next() % 8), in.next() % 3};
    bool rightShape = layout == ProbeLayout::Cross ? (w * 4 == h * 3 && w % 3 == 0) || (w * 3 == h * 4 && w % 4 == 0)
                                               : w == h && w >= 2;
    try {
      img = probeToLatLong(img, layout, c);
      w = img.width, h = img.height;  // the pixel edges the density check stays away from
      check(rightShape, "a probe of the wrong shape was converted");
      for (float v : img.rgb) check(std::isfinite(v) && v >= 0.f, "a probe's lat-long texel is negative or not finite");
    } catch (const std::runtime_error&) {
      check(!rightShape, "a probe of the right shape was refused");
    }
  }
  try {
    EnvironmentMap map(std::move(img), opts);
    map.setPoints(collapseByMedianCut(map, 1 + in.next() % 8));
    EnvironmentMapView view = map.view();
    static const EnvStrategy kAll[] = {EnvStrategy::Uniform,  EnvStrategy::Cosine, EnvStrategy::Importance,
                                       EnvStrategy::Alias,    EnvStrategy::Adaptive, EnvStrategy::Product,
                                       EnvStrategy::Points};
    for (int k = 0; k < 8 && in.n > 0; ++k) {
      Vec2f u(in.unit(), in.unit());
      Vec3f normal(in.unit() - 0.5f, in.unit() - 0.5f, in.unit() - 0.5f);
      if (in.next() % 4 == 0) normal = Vec3f(0.f);  // a BSDF that transmits: the whole sphere
      else if (length(normal) > 0.f) normal = normalize(normal);
      else normal = Vec3f(0.f, 1.f, 0.f);
      for (EnvStrategy s : kAll) {
        EnvSample smp = view.sample(s, u, normal);
        check(std::isfinite(smp.pdf) && smp.pdf >= 0.f, "sample pdf not finite or negative");
        check(finite(smp.radiance) && smp.radiance.x >= 0.f && smp.radiance.y >= 0.f && smp.radiance.z >= 0.f,
              "sample radiance not finite or negative");
        if (smp.pdf > 0.f) {
          check(std::fabs(length(smp.dir) - 1.f) < 1e-3f, "sampled direction not of unit length");
          if (!smp.delta) {
            float p = view.pdf(s, smp.dir, normal);
            check(std::isfinite(p) && p >= 0.f, "pdf of a drawn direction not finite or negative");
            // The density a draw reports is the one pdf() gives its direction, away from pixel
            // edges and the poles (where the round trip through a direction may change pixel).
            float fx = smp.uv.x * float(w), fy = smp.uv.y * float(h);
            float ex = std::fabs(fx - std::round(fx)), ey = std::fabs(fy - std::round(fy));
            if (ex > 1e-3f && ey > 1e-3f && smp.uv.y > 1e-3f && smp.uv.y < 1.f - 1e-3f && smp.pdf > 1e-6f &&
                smp.pdf < 1e6f && std::fabs(p - smp.pdf) > 1e-2f * smp.pdf) {
              std::fprintf(stderr, "fuzz_envmap: strategy %d drew pdf %g, pdf() gives %g at uv (%g, %g)\n", int(s),
                           smp.pdf, p, smp.uv.x, smp.uv.y);
              std::abort();
            }
            float q = 0.f;
            Color l = view.evalWithPdf(s, smp.dir, normal, &q);
            check(finite(l) && std::isfinite(q) && q >= 0.f, "evalWithPdf not finite");
          }
        }
      }
    }
  } catch (const std::runtime_error&) {
  }
  return 0;
}
