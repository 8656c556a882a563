// Host side of the environment light: loads and sanitises a lat-long map and builds the
// sampling structures that EnvironmentMapView reads.
#pragma once

#include <string>

#include "envmap/EnvironmentMapView.h"
#include "image/Image.h"

namespace envgi {

enum class ProbeLayout;  // envmap/LightProbe.h, kept out of the device code's includes

struct EnvironmentMapOptions {
  float scale = 1.f;
  Transform toWorld;
  bool bilinear = true;
  // Karlik et al. 2019: sample max(L - mean, 0), leaving the flat part to BSDF sampling.
  bool misCompensation = false;
  int adaptiveLeaves = 256;
};

struct EnvironmentMapStats {
  int width = 0, height = 0;
  Color channelMin, channelMax;
  Color power;             // integral of L over the sphere, per channel (W/m^2 for unit area)
  float lumMin = 0, lumMax = 0, lumMeanSolidAngle = 0, lumMedian = 0;
  float top1PercentEnergy = 0;  // fraction of solid-angle-weighted luminance in the brightest 1% of pixels
  size_t invalidPixels = 0;
};

class EnvironmentMap {
 public:
  // A lat-long file, read as Mitsuba's envmap reads it: with a bilinear lookup, its rows lie on
  // a grid from pole to pole (rowsAtPixelCentres). Throws std::runtime_error for an unreadable
  // file or a negative scale.
  static EnvironmentMap load(const std::string& path, const EnvironmentMapOptions& opts = {});
  // A square light probe (angular map or mirror ball), resampled to a lat-long map at twice its
  // width (probeToLatLong); throws as probeToLatLong and load() do.
  static EnvironmentMap loadProbe(const std::string& path, ProbeLayout layout, const EnvironmentMapOptions& opts = {});
  // load() for layout "latlong", loadProbe() for a probe layout's name (parseProbeLayout): the
  // scene's envmap and the envmap commands read a file so.
  static EnvironmentMap loadLayout(const std::string& path, const std::string& layout,
                                   const EnvironmentMapOptions& opts = {});
  // A map of constant radiance (small, so that the sin-theta weighting still applies).
  static EnvironmentMap constant(Color radiance, const EnvironmentMapOptions& opts = {});

  EnvironmentMap(Image img, const EnvironmentMapOptions& opts, const std::string& name = "map");
  EnvironmentMap(const EnvironmentMap&) = delete;
  EnvironmentMap& operator=(const EnvironmentMap&) = delete;
  EnvironmentMap(EnvironmentMap&&) = default;
  EnvironmentMap& operator=(EnvironmentMap&&) = default;

  EnvironmentMapView view() const;
  // Moves and rescales the map (the viewer's controls); the sampling tables, in the map's own
  // frame, stay valid. Throws for a negative scale.
  void setPlacement(float scale, const Transform& toWorld);
  // The texels the lookup reads (a copy): for a file, its own rows on Mitsuba's grid.
  Image image() const;
  int width() const { return width_; }
  int height() const { return height_; }
  const EnvironmentMapOptions& options() const { return opts_; }
  size_t invalidPixels() const { return invalid_; }
  EnvironmentMapStats stats() const;
  // Luminance power, integral of Y(L) over the sphere (zero for an all-black map).
  float luminancePower() const;
  size_t samplingBytes() const {
    return dist_.bytes() + paperDist_.bytes() + alias_.bytes() + emission_.bytes() + product_.bytes() + warpBits_.size() * sizeof(uint32_t);
  }

  // The collapsed map that the `points` strategy uses (envmap/CollapsedMap.h makes one).
  // Fills each light's selection pmf and cdf (by luminance; uniform when all are black).
  void setPoints(std::vector<DirectionalLight> points);
  const std::vector<DirectionalLight>& points() const { return points_; }

  // Mitsuba's envmap puts row j of an H-row map at v = j / (H - 1), on a grid that ends at the
  // poles, and interpolates linearly between rows; envgi's lookup (and so its sampling tables
  // and in-pixel warp) puts rows at pixel centres, v = (j + 0.5) / H. This resamples the rows to
  // pixel centres, each row Mitsuba's lookup at that centre: the map that load() builds the
  // sampling tables and the in-pixel warp from, while its lookup reads the file's rows where
  // Mitsuba does. Columns need nothing: both put them at pixel centres.
  static Image rowsAtPixelCentres(const Image& poleToPole);

  // Per-pixel sampling weight: luminance of the lookup's average over the pixel, times sin theta.
  static std::vector<float> samplingWeights(const Image& img, bool bilinear, bool misCompensation);

 private:
  // 4 floats a pixel (EnvironmentMapView::texels): the lookup's r, g, b and the density's
  // luminance. For a lat-long file the r, g, b are its rows on Mitsuba's grid from pole to pole
  // and the luminance is of those rows resampled to pixel centres (rowsFromPoles_).
  int width_ = 0, height_ = 0;
  std::vector<float> texels_;
  bool rowsFromPoles_ = false;
  // Writes img's r, g, b (the map's size) into the texels' lookup channels.
  void setLookupRgb(const Image& img);
  Color texelAt(int x, int y) const {
    const float* p = &texels_[(size_t(y) * width_ + x) * 4];
    return {p[0], p[1], p[2]};
  }
  EnvironmentMapOptions opts_;
  PiecewiseConstant2D dist_;
  PiecewiseConstant2D paperDist_;  // Algorithm 1's table, from the lookup's own pixels
  // Builds paperDist_ from the texels' r, g, b (the file's pixels).
  void buildAlgorithm1Table();
  AliasTable alias_;
  AliasTable emission_;  // plain luminance; built only when alias_ is compensated
  CosineProduct product_;
  std::vector<uint32_t> warpBits_;  // bilinear lookup: the pixels whose draws follow it (warpInPixel)
  std::vector<DirectionalLight> points_;
  AdaptiveQuadtree adaptive_;
  size_t invalid_ = 0;
};

}  // namespace envgi
