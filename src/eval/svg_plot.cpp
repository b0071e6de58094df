#include "eval/svg_plot.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <limits>

#include "eval/colormap.h"
#include "eval/eval_error.h"
#include "eval/markup_escape.h"

namespace edgeslam {
namespace {

constexpr double kWidth = 980.0;
constexpr double kHeight = 790.0;
// Plot area (data), leaving room for the title above, tick labels left/below, colour bar right.
constexpr double kLeft = 80.0;
constexpr double kTop = 84.0;
constexpr double kRight = 800.0;
constexpr double kBottom = 690.0;
constexpr int kColourLevels = 64;

// 1, 2 or 5 times a power of ten, near `raw`.
double niceStep(double raw) {
  if (!(raw > 0.0)) return 1.0;
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / power;
  return (f < 1.5 ? 1.0 : f < 3.5 ? 2.0 : f < 7.5 ? 5.0 : 10.0) * power;
}

std::string formatLength(double metres) {
  if (metres >= 1000.0) return fmt::format("{:g} km", metres / 1000.0);
  if (metres >= 1.0) return fmt::format("{:g} m", metres);
  if (metres >= 0.01) return fmt::format("{:g} cm", metres * 100.0);
  return fmt::format("{:g} mm", metres * 1000.0);
}

std::string formatTick(double value, double step) {
  const int decimals = std::max(0, -static_cast<int>(std::floor(std::log10(step) + 1e-9)));
  return fmt::format("{:.{}f}", std::abs(value) < step * 1e-6 ? 0.0 : value, decimals);
}

struct View {
  int h_axis = 0;
  int v_axis = 1;
  double h_min = 0.0;
  double v_min = 0.0;
  double pixels_per_metre = 1.0;
  double origin_x = kLeft;    // pixel of h_min
  double origin_y = kBottom;  // pixel of v_min

  double x(const Eigen::Vector3d& p) const {
    return origin_x + (p[h_axis] - h_min) * pixels_per_metre;
  }
  double y(const Eigen::Vector3d& p) const {
    return origin_y - (p[v_axis] - v_min) * pixels_per_metre;
  }
};

View makeView(const TrajectoryPlot& plot) {
  View view;
  if (plot.plane == PlotPlane::kXZ) {
    view.h_axis = 0;
    view.v_axis = 2;
  } else {
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
    Eigen::Vector3d hi = -lo;
    for (const auto& p : plot.ground_truth) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    std::array<int, 3> axes = {0, 1, 2};
    const Eigen::Vector3d extent = hi - lo;
    std::stable_sort(axes.begin(), axes.end(), [&](int a, int b) { return extent[a] > extent[b]; });
    view.h_axis = std::min(axes[0], axes[1]);
    view.v_axis = std::max(axes[0], axes[1]);
  }
  double h_lo = std::numeric_limits<double>::max();
  double h_hi = -h_lo;
  double v_lo = h_lo;
  double v_hi = -h_lo;
  for (const auto* points : {&plot.ground_truth, &plot.estimate}) {
    for (const auto& p : *points) {
      h_lo = std::min(h_lo, p[view.h_axis]);
      h_hi = std::max(h_hi, p[view.h_axis]);
      v_lo = std::min(v_lo, p[view.v_axis]);
      v_hi = std::max(v_hi, p[view.v_axis]);
    }
  }
  const double span = std::max({h_hi - h_lo, v_hi - v_lo, 1e-6});
  const double pad = 0.06 * span;
  const double h_span = h_hi - h_lo + 2.0 * pad;
  const double v_span = v_hi - v_lo + 2.0 * pad;
  view.pixels_per_metre = std::min((kRight - kLeft) / h_span, (kBottom - kTop) / v_span);
  // Centre the data in the plot area (equal scale on both axes).
  view.h_min = 0.5 * (h_lo + h_hi) - 0.5 * (kRight - kLeft) / view.pixels_per_metre;
  view.v_min = 0.5 * (v_lo + v_hi) - 0.5 * (kBottom - kTop) / view.pixels_per_metre;
  return view;
}

void drawGrid(std::string& svg, const View& view, const char* axis_names) {
  const double step = niceStep(80.0 / view.pixels_per_metre);
  const double h_max = view.h_min + (kRight - kLeft) / view.pixels_per_metre;
  const double v_max = view.v_min + (kBottom - kTop) / view.pixels_per_metre;
  svg += "<g stroke=\"#e3e6ea\" stroke-width=\"1\">\n";
  std::string labels;
  for (double h = std::ceil(view.h_min / step) * step; h <= h_max; h += step) {
    const double px = view.origin_x + (h - view.h_min) * view.pixels_per_metre;
    svg += fmt::format("<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\"/>\n", px,
                       kTop, px, kBottom);
    labels += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\">{}</text>\n", px,
                          kBottom + 18.0, formatTick(h, step));
  }
  for (double v = std::ceil(view.v_min / step) * step; v <= v_max; v += step) {
    const double py = view.origin_y - (v - view.v_min) * view.pixels_per_metre;
    svg += fmt::format("<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\"/>\n", kLeft,
                       py, kRight, py);
    labels += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"end\">{}</text>\n",
                          kLeft - 6.0, py + 4.0, formatTick(v, step));
  }
  svg += "</g>\n<g font-size=\"11\" fill=\"#5f6670\">\n" + labels + "</g>\n";
  svg += fmt::format(
      "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#9aa1a9\"/>\n",
      kLeft, kTop, kRight - kLeft, kBottom - kTop);
  svg += fmt::format(
      "<text x=\"{:.1f}\" y=\"{:.1f}\" font-size=\"13\" text-anchor=\"middle\" "
      "fill=\"#333\">{} [m]</text>\n",
      0.5 * (kLeft + kRight), kBottom + 40.0, axis_names[view.h_axis]);
  svg += fmt::format(
      "<text x=\"{:.1f}\" y=\"{:.1f}\" font-size=\"13\" text-anchor=\"middle\" fill=\"#333\" "
      "transform=\"rotate(-90 {:.1f} {:.1f})\">{} [m]</text>\n",
      kLeft - 52.0, 0.5 * (kTop + kBottom), kLeft - 52.0, 0.5 * (kTop + kBottom),
      axis_names[view.v_axis]);
}

std::string polylinePoints(const std::vector<Eigen::Vector3d>& points, std::size_t begin,
                           std::size_t end, const View& view) {
  std::string out;
  for (std::size_t i = begin; i < end; ++i) {
    out += fmt::format("{:.1f},{:.1f} ", view.x(points[i]), view.y(points[i]));
  }
  return out;
}

// Consecutive segments of the same colour level become one polyline, keeping the file small.
void drawEstimate(std::string& svg, const TrajectoryPlot& plot, const View& view, double e_hi) {
  const auto& est = plot.estimate;
  const auto level = [&](std::size_t segment) {
    const double e = 0.5 * (plot.errors[segment] + plot.errors[segment + 1]);
    const double t = e_hi > 0.0 ? e / e_hi : 0.0;
    return std::clamp(static_cast<int>(t * kColourLevels), 0, kColourLevels - 1);
  };
  svg +=
      "<g fill=\"none\" stroke-width=\"2.6\" stroke-linecap=\"round\" "
      "stroke-linejoin=\"round\">\n";
  std::size_t run_start = 0;
  for (std::size_t s = 0; s + 1 < est.size(); ++s) {
    const bool run_ends = s + 2 == est.size() || level(s + 1) != level(s);
    if (!run_ends) continue;
    const double t = (level(s) + 0.5) / kColourLevels;
    svg += fmt::format("<polyline stroke=\"{}\" points=\"{}\"/>\n", toHex(errorColormap(t)),
                       polylinePoints(est, run_start, s + 2, view));
    run_start = s + 1;
  }
  svg += "</g>\n";
}

void drawMarkers(std::string& svg, const TrajectoryPlot& plot, const View& view) {
  const auto& gt = plot.ground_truth;
  const auto& est = plot.estimate;
  if (!gt.empty()) {
    svg += fmt::format(
        "<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"7\" fill=\"#2ca02c\" stroke=\"white\" "
        "stroke-width=\"2\"/>\n",
        view.x(gt.front()), view.y(gt.front()));
    svg += fmt::format(
        "<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"12\" height=\"12\" fill=\"#d62728\" "
        "stroke=\"white\" stroke-width=\"2\"/>\n",
        view.x(gt.back()) - 6.0, view.y(gt.back()) - 6.0);
  }
  if (!est.empty()) {
    svg += fmt::format(
        "<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"5\" fill=\"none\" stroke=\"#2ca02c\" "
        "stroke-width=\"2\"/>\n",
        view.x(est.front()), view.y(est.front()));
    svg += fmt::format(
        "<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"10\" height=\"10\" fill=\"none\" "
        "stroke=\"#d62728\" stroke-width=\"2\"/>\n",
        view.x(est.back()) - 5.0, view.y(est.back()) - 5.0);
  }
}

void drawScaleBar(std::string& svg, const View& view) {
  const double metres = niceStep(0.2 * (kRight - kLeft) / view.pixels_per_metre);
  const double length = metres * view.pixels_per_metre;
  const double x0 = kLeft + 18.0;
  const double y0 = kBottom - 20.0;
  svg += fmt::format(
      "<g stroke=\"#222\" stroke-width=\"2\"><line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{2:.1f}\" "
      "y2=\"{1:.1f}\"/><line x1=\"{0:.1f}\" y1=\"{3:.1f}\" x2=\"{0:.1f}\" y2=\"{4:.1f}\"/>"
      "<line x1=\"{2:.1f}\" y1=\"{3:.1f}\" x2=\"{2:.1f}\" y2=\"{4:.1f}\"/></g>\n",
      x0, y0, x0 + length, y0 - 5.0, y0 + 5.0);
  svg += fmt::format(
      "<text x=\"{:.1f}\" y=\"{:.1f}\" font-size=\"12\" text-anchor=\"middle\" "
      "fill=\"#222\">{}</text>\n",
      x0 + 0.5 * length, y0 - 9.0, formatLength(metres));
}

// One row below the x-axis label, so that it never hides part of the trajectories.
void drawLegend(std::string& svg) {
  const double y = kBottom + 70.0;
  double x = kLeft;
  svg += "<g font-size=\"12\" fill=\"#222\">\n";
  svg += fmt::format(
      "<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{2:.1f}\" y2=\"{1:.1f}\" stroke=\"#7f7f7f\" "
      "stroke-width=\"4\"/><text x=\"{3:.1f}\" y=\"{4:.1f}\">ground truth</text>\n",
      x, y, x + 30.0, x + 38.0, y + 4.0);
  x += 130.0;
  svg += fmt::format(
      "<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"30\" height=\"3.5\" fill=\"url(#errgrad-h)\"/>"
      "<text x=\"{:.1f}\" y=\"{:.1f}\">estimate, coloured by error</text>\n",
      x, y - 1.75, x + 38.0, y + 4.0);
  x += 210.0;
  svg += fmt::format(
      "<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"6\" fill=\"#2ca02c\"/><text x=\"{:.1f}\" "
      "y=\"{:.1f}\">start</text>\n",
      x + 6.0, y, x + 17.0, y + 4.0);
  x += 65.0;
  svg += fmt::format(
      "<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"11\" height=\"11\" fill=\"#d62728\"/><text "
      "x=\"{:.1f}\" y=\"{:.1f}\">end (ground truth)</text>\n",
      x, y - 5.5, x + 17.0, y + 4.0);
  x += 140.0;
  svg += fmt::format(
      "<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"9\" height=\"9\" fill=\"none\" "
      "stroke=\"#d62728\" stroke-width=\"2\"/><text x=\"{:.1f}\" y=\"{:.1f}\">end "
      "(estimate)</text>\n",
      x + 1.0, y - 4.5, x + 17.0, y + 4.0);
  svg += "</g>\n";
}

// Vertical bar from 0 to the largest error, ticks at round values, the maximum marked.
void drawColourBar(std::string& svg, double e_hi, const std::string& label) {
  const double x = kRight + 40.0;
  const double top = kTop + 30.0;
  const double bottom = kBottom - 30.0;
  svg += fmt::format(
      "<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"22\" height=\"{:.1f}\" fill=\"url(#errgrad-v)\" "
      "stroke=\"#666\" stroke-width=\"0.8\"/>\n",
      x, top, bottom - top);
  svg += fmt::format(
      "<text x=\"{:.1f}\" y=\"{:.1f}\" font-size=\"13\" text-anchor=\"middle\" "
      "fill=\"#333\">{}</text>\n",
      x + 11.0, top - 14.0, escapeMarkup(label));
  if (!(e_hi > 0.0)) e_hi = 1.0;
  const double step = niceStep(e_hi / 5.0);
  const auto pixel = [&](double value) { return bottom - value / e_hi * (bottom - top); };
  svg += "<g font-size=\"11\" fill=\"#333\">\n";
  for (double value = 0.0; value <= e_hi * (1.0 + 1e-9); value += step) {
    if (value > 0.0 && pixel(value) - top < 14.0) break;  // would collide with the max label
    svg += fmt::format(
        "<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{2:.1f}\" y2=\"{1:.1f}\" stroke=\"#666\"/>"
        "<text x=\"{3:.1f}\" y=\"{4:.1f}\">{5}</text>\n",
        x + 22.0, pixel(value), x + 27.0, x + 30.0, pixel(value) + 4.0, formatTick(value, step));
  }
  svg += fmt::format(
      "<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{2:.1f}\" y2=\"{1:.1f}\" stroke=\"#666\"/>"
      "<text x=\"{3:.1f}\" y=\"{4:.1f}\" font-weight=\"bold\">max {5:.3g}</text>\n",
      x + 22.0, top, x + 27.0, x + 30.0, top + 4.0, e_hi);
  svg += "</g>\n";
}

std::string gradientDefinitions() {
  std::string stops;
  for (int i = 0; i <= 10; ++i) {
    const double t = i / 10.0;
    stops += fmt::format("<stop offset=\"{:.2f}\" stop-color=\"{}\"/>", t, toHex(errorColormap(t)));
  }
  return fmt::format(
      "<defs><linearGradient id=\"errgrad-v\" x1=\"0\" y1=\"1\" x2=\"0\" y2=\"0\">{0}"
      "</linearGradient><linearGradient id=\"errgrad-h\" x1=\"0\" y1=\"0\" x2=\"1\" y2=\"0\">{0}"
      "</linearGradient>"
      "</defs>\n",
      stops);
}

}  // namespace

std::string renderTrajectorySvg(const TrajectoryPlot& plot) {
  if (plot.ground_truth.empty() && plot.estimate.empty()) {
    throw EvalError("nothing to plot: both trajectories are empty");
  }
  if (plot.errors.size() != plot.estimate.size()) {
    throw EvalError(fmt::format("plot has {} estimate positions but {} errors",
                                plot.estimate.size(), plot.errors.size()));
  }
  const View view = makeView(plot);
  // Colours run from 0 (errors are distances) to the largest error.
  const double e_hi =
      plot.errors.empty() ? 0.0 : *std::max_element(plot.errors.begin(), plot.errors.end());

  std::string svg = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" "
      "viewBox=\"0 0 {0} {1}\" font-family=\"Helvetica, Arial, sans-serif\">\n",
      kWidth, kHeight);
  svg += gradientDefinitions();
  svg += fmt::format("<rect width=\"{}\" height=\"{}\" fill=\"white\"/>\n", kWidth, kHeight);
  svg += fmt::format(
      "<text x=\"{:.1f}\" y=\"34\" font-size=\"20\" font-weight=\"bold\" fill=\"#111\">{}</text>\n",
      kLeft, escapeMarkup(plot.title));
  svg += fmt::format("<text x=\"{:.1f}\" y=\"58\" font-size=\"13\" fill=\"#555\">{}</text>\n",
                     kLeft, escapeMarkup(plot.subtitle));
  static constexpr const char kAxisNames[] = "xyz";
  drawGrid(svg, view, kAxisNames);

  svg += fmt::format(
      "<clipPath id=\"plot-area\"><rect x=\"{}\" y=\"{}\" width=\"{}\" "
      "height=\"{}\"/></clipPath>\n<g clip-path=\"url(#plot-area)\">\n",
      kLeft, kTop, kRight - kLeft, kBottom - kTop);
  if (plot.ground_truth.size() >= 2) {
    svg += fmt::format(
        "<polyline fill=\"none\" stroke=\"#7f7f7f\" stroke-width=\"4\" stroke-opacity=\"0.75\" "
        "stroke-linecap=\"round\" stroke-linejoin=\"round\" points=\"{}\"/>\n",
        polylinePoints(plot.ground_truth, 0, plot.ground_truth.size(), view));
  }
  if (plot.estimate.size() >= 2) drawEstimate(svg, plot, view, e_hi);
  drawMarkers(svg, plot, view);
  svg += "</g>\n";
  drawScaleBar(svg, view);
  drawLegend(svg);
  drawColourBar(svg, e_hi, plot.error_label);
  svg += "</svg>\n";
  return svg;
}

void writeTrajectorySvg(const std::filesystem::path& path, const TrajectoryPlot& plot) {
  const std::string svg = renderTrajectorySvg(plot);
  if (path.has_parent_path()) {
    std::error_code ec;
    std::filesystem::create_directories(path.parent_path(), ec);
  }
  std::ofstream out(path);
  if (!out) throw EvalError(fmt::format("cannot write plot {}", path.string()));
  out << svg;
  if (!out) throw EvalError(fmt::format("failed writing plot {}", path.string()));
}

}  // namespace edgeslam
