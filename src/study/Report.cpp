#include "study/Report.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>
#include <functional>
#include <iterator>
#include <cmath>
#include <map>
#include <set>

#include "image/FalseColour.h"
#include "study/ErrorMetrics.h"

namespace envgi {

std::string base64(const std::string& in) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((in.size() + 2) / 3 * 4);
  for (size_t i = 0; i < in.size(); i += 3) {
    uint32_t v = uint32_t(uint8_t(in[i])) << 16;
    if (i + 1 < in.size()) v |= uint32_t(uint8_t(in[i + 1])) << 8;
    if (i + 2 < in.size()) v |= uint32_t(uint8_t(in[i + 2]));
    out += t[(v >> 18) & 63];
    out += t[(v >> 12) & 63];
    out += i + 1 < in.size() ? t[(v >> 6) & 63] : '=';
    out += i + 2 < in.size() ? t[v & 63] : '=';
  }
  return out;
}

namespace {

const char* kColours[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};

// A series' colour from its name alone, so a strategy keeps its colour from one report to the
// next: the render strategies a colour each; the collapsed map's sizes a ramp by log2 N (green
// for points-N, brown for points-draw-N); any other name by its hash.
std::string seriesColour(const std::string& name) {
  static const char* kNamed[] = {"uniform", "cosine", "bsdf", "adaptive", "importance", "alias", "mis", "product",
                                 "importance-bilinear"};
  for (size_t i = 0; i < std::size(kNamed); ++i)
    if (name == kNamed[i]) return kColours[i];
  for (const char* base : {"points-draw-", "points-"}) {
    if (name.rfind(base, 0) != 0) continue;
    const double n = std::atof(name.c_str() + std::strlen(base));
    const double t = std::clamp(std::log2(std::max(n, 1.0)) / 14.0, 0.0, 1.0);  // N from 1 to 16384
    const bool draw = std::string(base) == "points-draw-";
    return fmt::format("hsl({},{}%,{:.0f}%)", draw ? 30 : 150, draw ? 55 : 60, 75.0 - 55.0 * t);
  }
  return kColours[std::hash<std::string>{}(name) % std::size(kColours)];
}

std::string escape(const std::string& s) {
  std::string o;
  for (char c : s) o += c == '<' ? std::string("&lt;") : c == '>' ? std::string("&gt;") : c == '&' ? std::string("&amp;") : std::string(1, c);
  return o;
}

std::string pngDataUri(const Image& img) {
  return "data:image/png;base64," + base64(encodePng(img.width, img.height, toneMapImage(img, {})));
}

// |L(a) - L(ref)| / (L(ref) + 0.05) through errorRamp (0 to 1).
std::string errorMapDataUri(const Image& a, const Image& ref) {
  return "data:image/png;base64," + base64(encodePng(a.width, a.height, errorMapRgb(a, ref)));
}

// The error maps' colour bar: the ramp from 0 to 1 with its ticks, as an SVG element.
std::string errorColourBar() {
  std::string o = R"s(<svg xmlns="http://www.w3.org/2000/svg" width="320" height="40" font-family="sans-serif" )s"
                  R"s(font-size="12"><defs><linearGradient id="errorRamp">)s";
  for (int i = 0; i <= 8; ++i) {
    const Color c = errorRamp(float(i) / 8.f);
    o += fmt::format(R"s(<stop offset="{:.3f}" stop-color="rgb({},{},{})"/>)s", i / 8.0, int(c.x * 255.f),
                     int(c.y * 255.f), int(c.z * 255.f));
  }
  o += R"s(</linearGradient></defs><rect x="10" y="4" width="300" height="14" fill="url(#errorRamp)"/>)s";
  for (int i = 0; i <= 4; ++i)
    o += fmt::format(R"s(<text x="{}" y="34" text-anchor="middle">{:g}{}</text>)s", 10 + 75 * i, i / 4.0,
                     i == 4 ? " or more" : "");
  return o + "</svg>";
}

double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

}  // namespace

std::string svgLogLogPlot(const std::string& title, const std::string& xLabel, const std::string& yLabel,
                          const std::vector<std::string>& names, const std::vector<std::vector<double>>& xs,
                          const std::vector<std::vector<double>>& ys) {
  const double W = 560, H = 360, L = 70, R = 150, T = 30, B = 50;
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
  for (size_t s = 0; s < xs.size(); ++s)
    for (size_t i = 0; i < xs[s].size(); ++i)
      if (xs[s][i] > 0 && ys[s][i] > 0) {
        x0 = std::min(x0, std::log10(xs[s][i]));
        x1 = std::max(x1, std::log10(xs[s][i]));
        y0 = std::min(y0, std::log10(ys[s][i]));
        y1 = std::max(y1, std::log10(ys[s][i]));
      }
  if (!(x1 >= x0)) x0 = 0, x1 = 1;
  if (!(y1 >= y0)) y0 = 0, y1 = 1;
  x0 = std::floor(x0), x1 = std::max(std::ceil(x1), x0 + 1);
  y0 = std::floor(y0), y1 = std::max(std::ceil(y1), y0 + 1);
  auto px = [&](double v) { return L + (std::log10(v) - x0) / (x1 - x0) * (W - L - R); };
  auto py = [&](double v) { return H - B - (std::log10(v) - y0) / (y1 - y0) * (H - T - B); };
  std::string o = fmt::format(R"s(<svg xmlns="http://www.w3.org/2000/svg" width="{}" height="{}" font-family="sans-serif" font-size="12">)s", W, H);
  o += fmt::format(R"s(<text x="{}" y="18" font-weight="bold">{}</text>)s", L, escape(title));
  o += fmt::format(R"s(<rect x="{}" y="{}" width="{}" height="{}" fill="none" stroke="#444"/>)s", L, T, W - L - R, H - T - B);
  for (double e = x0; e <= x1 + 1e-9; e += 1) {
    double x = L + (e - x0) / (x1 - x0) * (W - L - R);
    o += fmt::format(R"s(<line x1="{0}" x2="{0}" y1="{1}" y2="{2}" stroke="#ddd"/><text x="{0}" y="{3}" text-anchor="middle">1e{4}</text>)s", x, T, H - B, H - B + 16, int(e));
  }
  for (double e = y0; e <= y1 + 1e-9; e += 1) {
    double y = H - B - (e - y0) / (y1 - y0) * (H - T - B);
    o += fmt::format(R"s(<line x1="{0}" x2="{1}" y1="{2}" y2="{2}" stroke="#ddd"/><text x="{3}" y="{4}" text-anchor="end">1e{5}</text>)s", L, W - R, y, L - 6, y + 4, int(e));
  }
  o += fmt::format(R"s(<text x="{}" y="{}" text-anchor="middle">{}</text>)s", L + (W - L - R) / 2, H - 10, escape(xLabel));
  o += fmt::format(R"s(<text x="14" y="{}" transform="rotate(-90 14 {})" text-anchor="middle">{}</text>)s", T + (H - T - B) / 2, T + (H - T - B) / 2, escape(yLabel));
  for (size_t s = 0; s < xs.size(); ++s) {
    const std::string c = seriesColour(names[s]);
    std::string pts;
    for (size_t i = 0; i < xs[s].size(); ++i)
      if (xs[s][i] > 0 && ys[s][i] > 0) pts += fmt::format("{:.1f},{:.1f} ", px(xs[s][i]), py(ys[s][i]));
    o += fmt::format(R"s(<polyline points="{}" fill="none" stroke="{}" stroke-width="2"/>)s", pts, c);
    for (size_t i = 0; i < xs[s].size(); ++i)
      if (xs[s][i] > 0 && ys[s][i] > 0) o += fmt::format(R"s(<circle cx="{:.1f}" cy="{:.1f}" r="3" fill="{}"/>)s", px(xs[s][i]), py(ys[s][i]), c);
    o += fmt::format(R"s(<rect x="{}" y="{}" width="12" height="12" fill="{}"/><text x="{}" y="{}">{}</text>)s", W - R + 10, T + 18 * s, c, W - R + 28, T + 18 * s + 11, escape(names[s]));
  }
  return o + "</svg>";
}

namespace {

// N of a points-N strategy (the collapsed map with every light at each point), else 0.
int collapsedMapSize(const std::string& strategy) {
  if (strategy.rfind("points-", 0) != 0 || strategy.rfind("points-draw", 0) == 0) return 0;
  try {
    return std::stoi(strategy.substr(7));
  } catch (...) {
    return 0;
  }
}

// The paper's trade made visible: RMSE against N for each sample count and each time budget,
// the other strategies as flat lines at their own RMSE, and, for each budget, whether the
// best collapsed map beats them.
std::string collapsedMapSection(const std::vector<StudyRun>& runs, const std::vector<std::string>& strategies) {
  std::vector<int> sizes;
  for (const std::string& s : strategies)
    if (int n = collapsedMapSize(s)) sizes.push_back(n);
  if (sizes.size() < 2) return "";
  std::sort(sizes.begin(), sizes.end());
  // Median RMSE by (strategy, budget): budget "N spp" or "T s".
  std::map<std::pair<std::string, std::string>, std::vector<double>> rmse;
  std::vector<std::string> budgets;
  for (const StudyRun& r : runs) {
    std::string b = r.timeBudget > 0 ? fmt::format("{:g} s", r.timeBudget) : fmt::format("{} spp", r.spp);
    rmse[{r.strategy, b}].push_back(r.rmse);
    if (std::find(budgets.begin(), budgets.end(), b) == budgets.end()) budgets.push_back(b);
  }
  std::vector<std::string> names;
  std::vector<std::vector<double>> xs, ys;
  std::string verdicts;
  for (const std::string& b : budgets) {
    std::vector<double> x, y;
    double bestPoints = INFINITY;
    int bestN = 0;
    for (int n : sizes)
      if (auto it = rmse.find({fmt::format("points-{}", n), b}); it != rmse.end()) {
        x.push_back(n);
        y.push_back(median(it->second));
        if (y.back() < bestPoints) bestPoints = y.back(), bestN = n;
      }
    if (x.size() < 2) continue;
    names.push_back("points-N, " + b);
    xs.push_back(x), ys.push_back(y);
    std::string beats, loses;
    for (const std::string& s : strategies) {
      if (collapsedMapSize(s) || !rmse.count({s, b})) continue;
      const double e = median(rmse[{s, b}]);
      names.push_back(s + ", " + b);
      xs.push_back({double(sizes.front()), double(sizes.back())});
      ys.push_back({e, e});
      (bestPoints < e ? beats : loses) += fmt::format("{}{} ({:.5f})", (bestPoints < e ? beats : loses).empty() ? "" : ", ",
                                                      escape(s), e);
    }
    verdicts += fmt::format("<li>{}: the best collapsed map is points-{} (RMSE {:.5f}); it beats {}{}.</li>", escape(b),
                            bestN, bestPoints, beats.empty() ? "none of the others" : beats,
                            loses.empty() ? "" : "; it loses to " + loses);
  }
  if (names.empty()) return "";
  return "<h2>The collapsed map against N</h2><p>Every one of N lights at each shading point (the paper's Section "
         "2.2): no noise between neighbouring pixels, a bias that falls as N grows and a cost that grows with it. "
         "Flat lines are the other strategies at the same budget.</p>" +
         svgLogLogPlot("RMSE against the collapsed map's N", "N (lights)", "RMSE", names, xs, ys) + "<ul>" + verdicts +
         "</ul>";
}

}  // namespace

std::string studyReportHtml(const std::string& scene, const std::vector<StudyRun>& runs, const Image& reference,
                            const std::vector<StudyImage>& images, const std::vector<std::string>& strategies,
                            const std::vector<std::pair<std::string, std::string>>& settings) {
  // Median over seeds for each (strategy, spp) and (strategy, time budget).
  std::map<std::pair<std::string, int>, std::vector<double>> bySpp, secBySpp, takenBySpp;
  std::map<std::pair<std::string, double>, std::vector<double>> byTime, secByTime;
  std::vector<int> sppList;
  for (const StudyRun& r : runs) {
    if (r.timeBudget > 0) {
      byTime[{r.strategy, r.timeBudget}].push_back(r.rmse);
      secByTime[{r.strategy, r.timeBudget}].push_back(r.seconds);
    } else {
      bySpp[{r.strategy, r.spp}].push_back(r.rmse);
      secBySpp[{r.strategy, r.spp}].push_back(r.seconds);
      takenBySpp[{r.strategy, r.spp}].push_back(r.samplesTaken());
      if (std::find(sppList.begin(), sppList.end(), r.spp) == sppList.end()) sppList.push_back(r.spp);
    }
  }
  std::sort(sppList.begin(), sppList.end());
  // With adaptive sampling a run takes fewer samples than its budget: plot and tabulate those.
  bool adaptive = false;
  for (const StudyRun& r : runs) adaptive = adaptive || r.samplesTaken() < double(r.spp);
  std::vector<std::vector<double>> xs, ys, tx, ty;
  for (const std::string& s : strategies) {
    std::vector<double> x, y, a, b;
    for (int n : sppList)
      if (bySpp.count({s, n})) {
        x.push_back(median(takenBySpp[{s, n}]));
        y.push_back(median(bySpp[{s, n}]));
      }
    for (auto& [k, v] : byTime)
      if (k.first == s) {
        a.push_back(median(secByTime[k]));
        b.push_back(median(v));
      }
    xs.push_back(x), ys.push_back(y), tx.push_back(a), ty.push_back(b);
  }
  std::string h = "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>envgi study: " + escape(scene) +
                  "</title><style>body{font-family:sans-serif;margin:24px}table{border-collapse:collapse}"
                  "td,th{border:1px solid #ccc;padding:4px 8px;text-align:right}figure{display:inline-block;margin:6px}"
                  "figcaption{font-size:12px;text-align:center}img{image-rendering:pixelated;width:192px}</style></head><body>";
  h += "<h1>Strategies compared: " + escape(scene) + "</h1>";
  if (!settings.empty()) {
    h += "<table>";
    for (const auto& [name, value] : settings) h += "<tr><th>" + escape(name) + "</th><td>" + escape(value) + "</td></tr>";
    h += "</table>";
  }
  // Times (and so the equal-time runs) are the device's: say which rendered the runs.
  std::set<std::string> devices;
  for (const StudyRun& r : runs) devices.insert(r.device.empty() ? "not recorded" : r.device);
  std::string deviceList;
  for (const std::string& d : devices) deviceList += (deviceList.empty() ? "" : "; ") + escape(d);
  h += "<p>Rendered on: " + deviceList + ".</p>";
  h += "<p>RMSE against the reference, median over seeds. Lower is better; a slope of -1/2 on the "
       "samples plot is an unbiased estimator's Monte Carlo rate, a flattening curve is bias (the "
       "collapsed map, <code>points-N</code>).</p>";
  if (adaptive)
    h += "<p>Adaptive sampling: each run stopped its converged pixels, so it took fewer samples than its "
         "budget. The samples plot and the table give the samples taken, a pixel's mean.</p>";
  h += svgLogLogPlot("RMSE against samples per pixel", adaptive ? "samples taken per pixel (mean)" : "samples per pixel",
                     "RMSE", strategies, xs, ys);
  bool anyTime = !byTime.empty();
  if (anyTime) h += svgLogLogPlot("RMSE against render time", "seconds", "RMSE", strategies, tx, ty);
  h += collapsedMapSection(runs, strategies);
  h += "<h2>Images</h2><div>";
  h += "<figure><img src=\"" + pngDataUri(reference) + "\"><figcaption>reference</figcaption></figure></div><div>";
  for (const StudyImage& im : images)
    h += fmt::format("<figure><img src=\"{}\"><figcaption>{} @ {} spp</figcaption></figure>", pngDataUri(im.image),
                     escape(im.strategy), im.spp);
  h += "</div><h3>Relative error |L - L<sub>ref</sub>| / (L<sub>ref</sub> + 0.05), 0 (blue) to 1 (red)</h3>" +
       errorColourBar() + "<div>";
  for (const StudyImage& im : images)
    h += fmt::format("<figure><img src=\"{}\"><figcaption>{} @ {} spp</figcaption></figure>",
                     errorMapDataUri(im.image, reference), escape(im.strategy), im.spp);
  h += "</div><h2>RMSE (median over seeds) and seconds</h2><table><tr><th>strategy</th>";
  for (int n : sppList) h += fmt::format("<th>{} spp</th>", n);
  h += "</tr>";
  for (const std::string& s : strategies) {
    h += "<tr><th>" + escape(s) + "</th>";
    for (int n : sppList)
      h += bySpp.count({s, n}) ? fmt::format("<td>{:.5f}<br><small>{:.2f} s{}</small></td>", median(bySpp[{s, n}]),
                                             median(secBySpp[{s, n}]),
                                             adaptive ? fmt::format(", {:.1f} spp taken", median(takenBySpp[{s, n}]))
                                                      : std::string())
                               : std::string("<td></td>");
    h += "</tr>";
  }
  h += "</table>";
  if (anyTime) {
    h += "<h2>Equal time</h2><table><tr><th>strategy</th><th>budget (s)</th><th>seconds</th><th>spp</th><th>RMSE</th>"
         "<th>worst of 4x4 regions</th></tr>";
    for (const StudyRun& r : runs)
      if (r.timeBudget > 0)
        h += fmt::format("<tr><th>{}</th><td>{}</td><td>{:.2f}</td><td>{}</td><td>{:.5f}</td><td>{:.5f}</td></tr>",
                         escape(r.strategy), r.timeBudget, r.seconds, r.spp, r.rmse, r.worstRegionRmse);
    h += "</table>";
  }
  return h + "</body></html>\n";
}

}  // namespace envgi
