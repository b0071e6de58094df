# Writes OUTPUT, a C++ file defining edgeslam::viz::webAssets() with the bytes of every file in
# WEB_DIR (index.html is served as "/"). Run with cmake -P at build time.
file(GLOB web_files RELATIVE ${WEB_DIR} ${WEB_DIR}/*.html ${WEB_DIR}/*.js ${WEB_DIR}/*.css)
list(SORT web_files)
set(arrays "")
set(entries "")
set(index 0)
foreach(name IN LISTS web_files)
  file(READ ${WEB_DIR}/${name} hex HEX)
  string(LENGTH "${hex}" hex_length)
  math(EXPR size "${hex_length} / 2")
  string(REGEX REPLACE "([0-9a-f][0-9a-f])" "'\\\\x\\1'," bytes "${hex}")
  string(REGEX REPLACE "(('\\\\x[0-9a-f][0-9a-f]',){16})" "\\1\n    " bytes "${bytes}")
  if(name MATCHES "\\.html$")
    set(type "text/html; charset=utf-8")
  elseif(name MATCHES "\\.js$")
    set(type "text/javascript; charset=utf-8")
  else()
    set(type "text/css; charset=utf-8")
  endif()
  if(name STREQUAL "index.html")
    set(path "/")
  else()
    set(path "/${name}")
  endif()
  string(APPEND arrays "// ${name}\nconstexpr char kAsset${index}[] = {\n    ${bytes}'\\0'};\n")
  string(APPEND entries
    "      {\"${path}\", \"${type}\", std::string_view(kAsset${index}, ${size})},\n")
  math(EXPR index "${index} + 1")
endforeach()
file(WRITE ${OUTPUT}.tmp "// Generated from web/ by src/viz/embed_web_assets.cmake; do not edit.
#include \"viz/web_assets.h\"

namespace edgeslam::viz {
namespace {
${arrays}
}  // namespace

const std::vector<WebAsset>& webAssets() {
  static const std::vector<WebAsset> assets = {
${entries}  };
  return assets;
}

}  // namespace edgeslam::viz
")
# Only a real change rebuilds what depends on it.
file(COPY_FILE ${OUTPUT}.tmp ${OUTPUT} ONLY_IF_DIFFERENT)
file(REMOVE ${OUTPUT}.tmp)
