// The study's report: a self-contained HTML page (inline SVG plots, images as data URIs) with
// the convergence plots against samples and against time, the image grid and the table.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "image/Image.h"

namespace envgi {

struct StudyRun {
  std::string strategy;
  int spp = 0;
  double timeBudget = 0.0;  // 0: an equal-samples run
  int seed = 0;
  double seconds = 0.0, rmse = 0.0, relMse = 0.0, worstRegionRmse = 0.0;
  std::string device{};  // what rendered it ("cpu", "cuda:0 (NVIDIA H200, regeneration)"): times depend on it
  // Samples taken a pixel, on average: spp, or fewer where adaptive sampling stopped pixels
  // (0: not recorded, read as spp).
  double meanSpp = 0.0;
  double samplesTaken() const { return meanSpp > 0.0 ? meanSpp : double(spp); }
};

struct StudyImage {
  std::string strategy;
  int spp = 0;
  Image image;
};

// Log-log plot of y against x, one polyline a series, as an SVG element.
std::string svgLogLogPlot(const std::string& title, const std::string& xLabel, const std::string& yLabel,
                          const std::vector<std::string>& names, const std::vector<std::vector<double>>& xs,
                          const std::vector<std::vector<double>>& ys);

// Bytes as base64 (data URIs for images inside the page).
std::string base64(const std::string& bytes);

// settings: how the study was made (the reference, -D values, size, seeds...), name and value,
// shown under the title so that a report read alone says what it measured.
std::string studyReportHtml(const std::string& scene, const std::vector<StudyRun>& runs, const Image& reference,
                            const std::vector<StudyImage>& images, const std::vector<std::string>& strategies,
                            const std::vector<std::pair<std::string, std::string>>& settings = {});

}  // namespace envgi
