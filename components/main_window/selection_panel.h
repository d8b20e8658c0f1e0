#pragma once
// The Main Window's "Selection" panel: the entity selected on the Model (picked in the Scene
// Renderer, in the parameter tree or by any client) with the edits it takes: a body's mass and
// shape dimensions, an obstacle's size and place, a path point's position, removing a tendon or a
// via point, adding a tendon, and a sensor delay on a joint's or a tendon's channels. Every edit is queued on the ModelLink; the Model validates it
// and a refused edit comes back as the link's last_error (the status bar), changing nothing.

#include <QDialog>
#include <QWidget>
#include <functional>
#include <string>
#include <vector>

#include "model_link.h"

class QComboBox;
class QDoubleSpinBox;
class QLabel;
class QLineEdit;
class QVBoxLayout;

namespace caliper::main_window {

/// Asks what a new tendon needs: its name and radius [mm], two bodies with a point in each [mm],
/// the actuator's kind (from the Model's registered kinds) and name.
class AddTendonDialog : public QDialog {
 public:
  /// `from_body` is the body chosen first ("" = the first moving body).
  AddTendonDialog(const SceneInfo& scene, const std::vector<ActuatorKindInfo>& kinds,
                  const std::string& from_body, QWidget* parent = nullptr);

  std::string tendon() const;
  std::string actuator() const;
  std::string kind() const;
  double radius_m() const;
  PathPointInfo from() const;
  PathPointInfo to() const;

 private:
  QLineEdit* tendon_ = nullptr;
  QLineEdit* actuator_ = nullptr;
  QComboBox* kind_ = nullptr;
  QDoubleSpinBox* radius_mm_ = nullptr;
  QComboBox* body_[2] = {nullptr, nullptr};
  QDoubleSpinBox* point_mm_[2][3] = {};
};

class SelectionPanel : public QWidget {
 public:
  explicit SelectionPanel(ModelLink& link, QWidget* parent = nullptr);

  /// Shows the selection of `s` anew (a new selection, or the scene was edited).
  void Rebuild(const Snapshot& s);
  /// Takes the live values it shows (the body's mass) from `s`.
  void UpdateValues(const Snapshot& s);
  /// The parameter ids whose values the panel shows: to be watched by the link.
  std::vector<std::string> watched() const;
  /// Opens the Add tendon dialog (not modal: the window keeps refreshing).
  void OpenAddTendon();
  /// Where the panel says what it did (the status bar).
  void set_message_handler(std::function<void(const QString&)> handler) {
    message_ = std::move(handler);
  }

 private:
  QDoubleSpinBox* Spin(const QString& name, double value, double scale, int decimals,
                       const QString& suffix);
  void Say(const QString& text);
  void BuildBody(const BodyInfo& body);
  void BuildObstacle(const ObstacleInfo& obstacle);
  void BuildTendon(const TendonInfo& tendon, const Snapshot& s);
  void BuildPathPoint(const TendonInfo& tendon, unsigned index);
  /// A "Sensor delay" row for the scalar state channels whose ids start with one of `names`
  /// (scene.daq_name.): a channel, its delay [ms] and Apply (set_measurement_delay); none without
  /// such channels.
  void BuildSensorDelay(const std::vector<std::string>& names, const Snapshot& s);

  ModelLink& link_;
  std::function<void(const QString&)> message_;
  QLabel* title_ = nullptr;
  QWidget* form_ = nullptr;  // rebuilt for each selection
  QVBoxLayout* form_layout_ = nullptr;
  QDoubleSpinBox* mass_ = nullptr;
  std::string mass_id_;     // <scene>.<body>.mass, "" when no body is shown
  double shown_mass_ = -1;  // the Model's mass last put in mass_ [kg]
  SceneInfo scene_;
  std::vector<ActuatorKindInfo> kinds_;
  SelectionInfo selection_;
};

/// "point 1 of biceps" style names of path elements: attachment, via point or wrap.
std::string PathElementName(const TendonInfo& tendon, unsigned index);

}  // namespace caliper::main_window
