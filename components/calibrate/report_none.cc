// Without the GUI build there is no Qwt: the report has its CSV files only.
#include "report.h"

namespace caliper::calibration {

std::string WritePng(const std::string&, const std::vector<Plot>&, int, int) {
  return "this build has no GUI (Qt5/Qwt): the report has CSV files only";
}

}  // namespace caliper::calibration
