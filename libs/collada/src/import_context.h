#pragma once
// State shared by the stages of one import: the document, its units and axes, the scene being
// built, where each scene element came from, and the error and warning helpers that name the
// file, line and element.

#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "caliper/sgal/scene.h"
#include "document.h"

namespace caliper::collada::internal {

class Context {
 public:
  Context(const Document& document, std::vector<std::string>* warnings)
      : doc(document), warnings_(warnings) {}

  const Document& doc;
  double meter = 1;                                  // metres per document unit
  Eigen::Matrix3d up = Eigen::Matrix3d::Identity();  // document axes -> Z up
  bool openrave = false;  // written by OpenRAVE (rigid bodies in the physics model's frame)
  sgal::Scene scene;

  // where each scene element came from (by its name in the scene), for messages
  std::map<std::string, const Element*> body_source;
  std::map<std::string, const Element*> constraint_source;
  std::map<std::string, const Element*> tendon_source;
  std::map<std::string, const Element*> actuator_source;
  std::map<std::string, const Element*> obstacle_source;

  // which body each node instance (index into VisualScene::nodes()) moves
  std::map<int, std::string> instance_body;
  // other names a body goes by in the document (node id and name, rigid body sid and name)
  std::map<std::string, std::string> body_alias;

  /// `preferred` if no body has that name yet, else `preferred_2`, `preferred_3`, ...
  std::string UniqueBodyName(const std::string& preferred) const;
  /// Adds a body to the scene, remembers its source element and aliases; returns its index.
  size_t AddBody(sgal::Body body, const Element* source, const std::vector<std::string>& aliases);
  /// The body a name from the document means (a body name or an alias); "" when none.
  std::string FindBody(const std::string& name) const;

  /// `file:line: element 'id'` (no line when it is not known; the file alone for null).
  std::string Where(const Element* e) const;
  /// Appends `Where(e): message` to the warnings.
  void Warn(const Element* e, const std::string& message) const;
  /// Warns the first time for `kind`, counts the later times (see ReportRepeated).
  void WarnRepeated(const std::string& kind, const Element* e, const std::string& message);
  /// Adds "N more: kind" for each kind warned about more than once.
  void ReportRepeated();
  /// Throws ImportError with `Where(e): message`.
  [[noreturn]] void Fail(const Element* e, const std::string& message) const;

  /// The element a URL attribute points to: "#id", or a bare "id" within the document. Throws
  /// ImportError naming `from` for an external or dangling reference.
  const Element& Resolve(const Element& from, const std::string& url) const;
  /// As Resolve, nullptr when the reference does not resolve (never throws).
  const Element* TryResolve(const std::string& url) const;

  /// The numbers of an element's character data; throws ImportError naming it when a token is
  /// not a number or (count > 0) when there are not exactly `count`.
  std::vector<double> Numbers(const Element& e, size_t count = 0) const;
  /// The single number of an element; `fallback` when `e` is null.
  double Number(const Element* e, double fallback) const;
  /// Three numbers (a vector) of an element.
  Eigen::Vector3d Vector3(const Element& e) const;
  /// A boolean (true/false/1/0) of an element; `fallback` when `e` is null.
  bool Bool(const Element* e, bool fallback) const;
  /// A non-negative integer attribute; `fallback` when absent. Throws ImportError naming `e`.
  size_t Count(const Element& e, const char* attribute, size_t fallback) const;

  /// A length in the document's unit to metres.
  double Length(double document_value) const { return document_value * meter; }

 private:
  std::vector<std::string>* warnings_;
  std::map<std::string, int> repeated_;  // kind -> times warned
};

}  // namespace caliper::collada::internal
