// The COLLADA 1.5.0 door to Collada-DOM: loads and writes through the ColladaDOM150 classes.
#include <1.5/dom/domCOLLADA.h>
#include <1.5/dom/domFloat_array.h>
#include <1.5/dom/domInt_array.h>
#include <1.5/dom/domP.h>
#include <1.5/dom/domPolygons.h>
#include <1.5/dom/domPolylist.h>

#include "dom_convert.h"

namespace caliper::collada::internal {

namespace {

// The DOM classes of COLLADA 1.5.0 that the shared code needs.
struct Dom150 {
  static constexpr const char* kVersion = "1.5.0";
  using Collada = ColladaDOM150::domCOLLADA;
  using FloatArray = ColladaDOM150::domFloat_array;
  using IntArray = ColladaDOM150::domInt_array;
  using P = ColladaDOM150::domP;
  using Vcount = ColladaDOM150::domPolylist::domVcount;
  using H = ColladaDOM150::domPolygons::domPh::domH;
};

}  // namespace

DomLoad LoadWithDom150(const std::string& path, bool zipped) {
  return LoadWithDom<Dom150>(path, zipped);
}

void WriteWithDom150(const Element& root, const std::string& path) {
  WriteWithDom<Dom150>(root, path);
}

}  // namespace caliper::collada::internal
