#include "eval/svg_plot.h"

#include <gtest/gtest.h>

#include "eval/colormap.h"
#include "eval/eval_error.h"

namespace edgeslam {
namespace {

TrajectoryPlot circlePlot() {
  TrajectoryPlot plot;
  plot.title = "ATE <test> & more";
  for (int i = 0; i <= 100; ++i) {
    const double a = 0.0628 * i;
    plot.ground_truth.emplace_back(3.0 * std::cos(a), 0.1, 2.0 * std::sin(a));
    plot.estimate.emplace_back(3.1 * std::cos(a), 0.1, 2.05 * std::sin(a));
    plot.errors.push_back(0.01 * i);
  }
  return plot;
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto pos = text.find(what); pos != std::string::npos; pos = text.find(what, pos + 1)) ++n;
  return n;
}

TEST(SvgPlot, DrawsBothTrajectoriesLegendAndEscapedTitle) {
  const std::string svg = renderTrajectorySvg(circlePlot());
  EXPECT_EQ(svg.rfind("<svg", 0), 0U);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_NE(svg.find("ATE &lt;test&gt; &amp; more"), std::string::npos);
  EXPECT_GE(count(svg, "<polyline"), 3U);  // ground truth + estimate runs of several colours
  EXPECT_NE(svg.find("errgrad-v"), std::string::npos);
  EXPECT_NE(svg.find("ground truth"), std::string::npos);
  // The ground truth spans x and z: those axes are drawn, y (constant) is not.
  EXPECT_NE(svg.find(">x [m]<"), std::string::npos);
  EXPECT_NE(svg.find(">z [m]<"), std::string::npos);
  // Colour bar runs from 0 to the largest error (1.0) in round steps.
  EXPECT_NE(svg.find(">0.0<"), std::string::npos);
  EXPECT_NE(svg.find(">0.6<"), std::string::npos);
  EXPECT_NE(svg.find(">max 1<"), std::string::npos);
  EXPECT_NE(svg.find("end (estimate)"), std::string::npos);
}

TEST(SvgPlot, ColoursFollowErrors) {
  const std::string svg = renderTrajectorySvg(circlePlot());
  EXPECT_NE(svg.find(toHex(errorColormap(0.5 / 64))), std::string::npos);
  EXPECT_NE(svg.find(toHex(errorColormap(63.5 / 64))), std::string::npos);
}

TEST(SvgPlot, RejectsMismatchedErrors) {
  TrajectoryPlot plot = circlePlot();
  plot.errors.pop_back();
  EXPECT_THROW(renderTrajectorySvg(plot), EvalError);
  EXPECT_THROW(renderTrajectorySvg(TrajectoryPlot{}), EvalError);
}

TEST(Colormap, GoesFromDarkToBright) {
  const Rgb lo = errorColormap(0.0);
  const Rgb hi = errorColormap(1.0);
  EXPECT_LT(lo.r + lo.g + lo.b, hi.r + hi.g + hi.b);
  EXPECT_EQ(toHex(errorColormap(-3.0)), toHex(lo));
  EXPECT_EQ(toHex(errorColormap(7.0)), toHex(hi));
  EXPECT_EQ(toHex({1.0, 0.0, 0.5}), "#ff0080");
}

}  // namespace
}  // namespace edgeslam
