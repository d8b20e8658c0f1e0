// The COLLADA 1.4.1 door to Collada-DOM: loads and writes through the ColladaDOM141 classes.
#include <1.4/dom/domCOLLADA.h>
#include <1.4/dom/domFloat_array.h>
#include <1.4/dom/domInt_array.h>
#include <1.4/dom/domP.h>
#include <1.4/dom/domPolygons.h>
#include <1.4/dom/domPolylist.h>

#include "dom_convert.h"

namespace caliper::collada::internal {

namespace {

// The DOM classes of COLLADA 1.4.1 that the shared code needs.
struct Dom141 {
  static constexpr const char* kVersion = "1.4.1";
  using Collada = ColladaDOM141::domCOLLADA;
  using FloatArray = ColladaDOM141::domFloat_array;
  using IntArray = ColladaDOM141::domInt_array;
  using P = ColladaDOM141::domP;
  using Vcount = ColladaDOM141::domPolylist::domVcount;
  using H = ColladaDOM141::domPolygons::domPh::domH;
};

}  // namespace

DomLoad LoadWithDom141(const std::string& path, bool zipped) {
  return LoadWithDom<Dom141>(path, zipped);
}

}  // namespace caliper::collada::internal
