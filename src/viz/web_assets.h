#pragma once
// The viewer's page, script and style (web/) and the libraries it loads (three.js, OrbitControls,
// uPlot from web/node_modules, served under /lib/), built into the binary (embed_web_assets.cmake
// writes web_assets.cpp), so that the binary serves them wherever it is copied, offline.
#include <string_view>
#include <vector>

namespace edgeslam::viz {

struct WebAsset {
  std::string_view path;  // as requested, e.g. "/app.js"; the page is "/"
  std::string_view content_type;
  std::string_view body;
};

const std::vector<WebAsset>& webAssets();

}  // namespace edgeslam::viz
