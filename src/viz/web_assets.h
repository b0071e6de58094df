#pragma once
// The viewer's page, script and style (web/), built into the binary (embed_web_assets.cmake
// writes web_assets.cpp), so that the binary serves them wherever it is copied.
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
