#pragma once
// Text made safe inside HTML, SVG or XML elements and double-quoted attributes.
#include <string>
#include <string_view>

namespace edgeslam {

std::string escapeMarkup(std::string_view text);

}  // namespace edgeslam
