// Without the GUI build there is no Qwt: no PNG, and a page of tables without pictures.
#include "report.h"
#include "report_html.h"

namespace caliper::calibration {

namespace {

constexpr const char* kNoGui = "this build has no GUI (Qt5/Qwt), so it draws no plots";

}  // namespace

std::string WritePng(const std::string&, const std::vector<Plot>&, int, int) {
  return "this build has no GUI (Qt5/Qwt): the report has CSV files only";
}

std::string WriteHtml(const std::string& path, const HtmlReport& report) {
  PagePictures pictures;
  pictures.none = kNoGui;
  return WriteHtmlPage(path, report, pictures);
}

}  // namespace caliper::calibration
