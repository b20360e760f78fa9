// The page's static files (src/view/page/), compiled in by embed_page.cmake so that the binary,
// the installed tree and the Python module serve the same page with nothing to find at run time.
#pragma once

#include <cstddef>

namespace emaki::view {

struct PageFile {
  const char* name;  // "index.html", "view.js", "view.css"
  const unsigned char* data;
  std::size_t size;
};

extern const PageFile kPageFiles[];
extern const int kPageFileCount;

}  // namespace emaki::view
