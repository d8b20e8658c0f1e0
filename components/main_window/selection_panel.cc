#include "selection_panel.h"

#include <QComboBox>
#include <QDialogButtonBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QGridLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QPushButton>
#include <QVBoxLayout>
#include <algorithm>
#include <cmath>
#include <set>

namespace caliper::main_window {

namespace {

constexpr double kMmPerM = 1000.0;
const char* const kAxes[3] = {"x", "y", "z"};

QPushButton* Button(const QString& text, const QString& name, QWidget* parent) {
  auto* b = new QPushButton(text, parent);
  b->setObjectName(name);
  return b;
}

QString Q(const std::string& s) { return QString::fromStdString(s); }

QString Mm(const PathPointInfo& p) {
  return QString("(%1, %2, %3) mm")
      .arg(p.x_m * kMmPerM, 0, 'g', 6)
      .arg(p.y_m * kMmPerM, 0, 'g', 6)
      .arg(p.z_m * kMmPerM, 0, 'g', 6);
}

QString ElementText(const PathPointInfo& p) {
  if (!p.obstacle.empty()) return "wrap around " + Q(p.obstacle);
  return (p.body.empty() ? QString("world") : Q(p.body)) + " " + Mm(p);
}

}  // namespace

std::string PathElementName(const TendonInfo& tendon, unsigned index) {
  const bool end = index == 0 || index + 1 == tendon.path.size();
  const bool wrap = index < tendon.path.size() && !tendon.path[index].obstacle.empty();
  return std::string(wrap  ? "wrap "
                     : end ? "attachment "
                           : "via point ") +
         std::to_string(index) + " of " + tendon.name;
}

// ------------------------------------------------------------------------ Add tendon dialog

AddTendonDialog::AddTendonDialog(const SceneInfo& scene, const std::vector<ActuatorKindInfo>& kinds,
                                 const std::string& from_body, QWidget* parent)
    : QDialog(parent) {
  setObjectName("add_tendon_dialog");
  setWindowTitle("Add tendon");
  auto* layout = new QVBoxLayout(this);
  auto* form = new QFormLayout;
  // a name no tendon or actuator has yet
  std::set<std::string> taken;
  for (const auto& t : scene.tendons) taken.insert(t.name);
  for (const auto& a : scene.actuators) taken.insert(a.name);
  std::string name = "tendon_1";
  for (int n = 1; taken.count(name) != 0 && n < 10000; ++n) name = "tendon_" + std::to_string(n);
  tendon_ = new QLineEdit(Q(name), this);
  tendon_->setObjectName("tendon_name");
  form->addRow("Tendon name", tendon_);
  radius_mm_ = new QDoubleSpinBox(this);
  radius_mm_->setObjectName("tendon_radius");
  radius_mm_->setDecimals(3);
  radius_mm_->setRange(0, 1000);
  radius_mm_->setValue(1.5);
  radius_mm_->setSuffix(" mm");
  form->addRow("Radius", radius_mm_);

  // the first end in `from_body` (or the first moving body), the second in another moving one
  int first = -1;
  int second = -1;
  for (int k = 0; k < static_cast<int>(scene.bodies.size()); ++k) {
    if (scene.bodies[k].name == from_body) first = k;
  }
  for (int k = 0; k < static_cast<int>(scene.bodies.size()); ++k) {
    if (!scene.bodies[k].moving) continue;
    if (first < 0) {
      first = k;
    } else if (second < 0 && k != first) {
      second = k;
    }
  }
  const char* const kEnds[2] = {"from", "to"};
  for (int end = 0; end < 2; ++end) {
    body_[end] = new QComboBox(this);
    body_[end]->setObjectName(QString(kEnds[end]) + "_body");
    for (const auto& b : scene.bodies) body_[end]->addItem(Q(b.name), Q(b.name));
    body_[end]->addItem("(world)", QString());
    const int chosen = end == 0 ? first : second;
    if (chosen >= 0) body_[end]->setCurrentIndex(chosen);
    auto* row = new QHBoxLayout;
    row->addWidget(body_[end], 1);
    for (int a = 0; a < 3; ++a) {
      auto* spin = new QDoubleSpinBox(this);
      spin->setObjectName(QString("%1_%2").arg(kEnds[end], kAxes[a]));
      spin->setDecimals(2);
      spin->setRange(-1e5, 1e5);
      spin->setPrefix(QString(kAxes[a]) + " ");
      spin->setSuffix(" mm");
      point_mm_[end][a] = spin;
      row->addWidget(spin);
    }
    form->addRow(end == 0 ? "From (point in the body's frame)" : "To (point in the body's frame)",
                 row);
  }

  kind_ = new QComboBox(this);
  kind_->setObjectName("actuator_kind");
  for (const auto& k : kinds) {
    QString defaults;
    for (size_t p = 0; p < k.parameters.size(); ++p)
      defaults += QString("%1%2 = %3 %4")
                      .arg(p == 0 ? "" : "\n", Q(k.parameters[p]))
                      .arg(k.defaults[p])
                      .arg(Q(k.units[p]));
    kind_->addItem(Q(k.kind), Q(k.kind));
    kind_->setItemData(kind_->count() - 1, defaults, Qt::ToolTipRole);
  }
  form->addRow("Actuator kind", kind_);
  actuator_ = new QLineEdit(Q(name), this);
  actuator_->setObjectName("actuator_name");
  actuator_->setToolTip("its parameters start at the kind's defaults: tune them in the tree");
  form->addRow("Actuator name", actuator_);
  layout->addLayout(form);
  auto* buttons = new QDialogButtonBox(QDialogButtonBox::Ok | QDialogButtonBox::Cancel, this);
  buttons->button(QDialogButtonBox::Ok)->setText("Add");
  connect(buttons, &QDialogButtonBox::accepted, this, &QDialog::accept);
  connect(buttons, &QDialogButtonBox::rejected, this, &QDialog::reject);
  layout->addWidget(buttons);
}

std::string AddTendonDialog::tendon() const { return tendon_->text().trimmed().toStdString(); }
std::string AddTendonDialog::actuator() const { return actuator_->text().trimmed().toStdString(); }
std::string AddTendonDialog::kind() const { return kind_->currentData().toString().toStdString(); }
double AddTendonDialog::radius_m() const { return radius_mm_->value() / kMmPerM; }

PathPointInfo AddTendonDialog::from() const {
  return PathPointInfo{body_[0]->currentData().toString().toStdString(),
                       point_mm_[0][0]->value() / kMmPerM, point_mm_[0][1]->value() / kMmPerM,
                       point_mm_[0][2]->value() / kMmPerM, ""};
}

PathPointInfo AddTendonDialog::to() const {
  return PathPointInfo{body_[1]->currentData().toString().toStdString(),
                       point_mm_[1][0]->value() / kMmPerM, point_mm_[1][1]->value() / kMmPerM,
                       point_mm_[1][2]->value() / kMmPerM, ""};
}

// ------------------------------------------------------------------------ Selection panel

SelectionPanel::SelectionPanel(ModelLink& link, QWidget* parent) : QWidget(parent), link_(link) {
  setObjectName("selection_panel");
  auto* layout = new QVBoxLayout(this);
  title_ = new QLabel(this);
  title_->setObjectName("selection_title");
  title_->setWordWrap(true);
  title_->setStyleSheet("QLabel { font-weight: bold; }");
  layout->addWidget(title_);
  form_ = new QWidget(this);
  form_layout_ = new QVBoxLayout(form_);
  form_layout_->setContentsMargins(0, 0, 0, 0);
  layout->addWidget(form_);
  layout->addStretch();
  auto* add = Button("Add tendon...", "add_tendon", this);
  add->setToolTip("a new tendon with an actuator between points of two bodies");
  connect(add, &QPushButton::clicked, this, [this] { OpenAddTendon(); });
  layout->addWidget(add);
  title_->setText("Nothing selected");
}

void SelectionPanel::Say(const QString& text) {
  if (message_) message_(text);
}

QDoubleSpinBox* SelectionPanel::Spin(const QString& name, double value, double scale, int decimals,
                                     const QString& suffix) {
  auto* spin = new QDoubleSpinBox(form_);
  spin->setObjectName(name);
  spin->setDecimals(decimals);
  // wide limits: the Model validates each edit and says why it refuses one
  spin->setRange(-1e6, 1e6);
  spin->setSuffix(suffix);
  spin->setValue(value * scale);
  return spin;
}

std::vector<std::string> SelectionPanel::watched() const {
  if (mass_id_.empty()) return {};
  return {mass_id_};
}

void SelectionPanel::Rebuild(const Snapshot& s) {
  scene_ = s.scene;
  kinds_ = s.actuator_kinds;
  selection_ = s.selection;
  // a fresh form for the selection: the widgets of the last one go
  delete form_layout_;
  for (QWidget* w : form_->findChildren<QWidget*>(QString(), Qt::FindDirectChildrenOnly)) delete w;
  form_layout_ = new QVBoxLayout(form_);
  form_layout_->setContentsMargins(0, 0, 0, 0);
  mass_ = nullptr;
  mass_id_.clear();
  shown_mass_ = -1;

  const SelectionInfo& sel = s.selection;
  if (sel.kind == "body") {
    if (const BodyInfo* b = scene_.FindBody(sel.name)) {
      BuildBody(*b);
      return;
    }
  } else if (sel.kind == "obstacle") {
    if (const ObstacleInfo* o = scene_.FindObstacle(sel.name)) {
      BuildObstacle(*o);
      return;
    }
  } else if (sel.kind == "tendon") {
    if (const TendonInfo* t = scene_.FindTendon(sel.name)) {
      BuildTendon(*t, s);
      return;
    }
  } else if (sel.kind == "path_point") {
    const TendonInfo* t = scene_.FindTendon(sel.name);
    if (t != nullptr && sel.index < t->path.size()) {
      BuildPathPoint(*t, sel.index);
      return;
    }
  } else if (sel.kind == "constraint") {
    title_->setText("Constraint " + Q(sel.name));
    form_layout_->addWidget(new QLabel("its parameters are in the tree", form_));
    BuildSensorDelay({sel.name}, s);
    return;
  }
  title_->setText(
      sel.kind.empty()
          ? QString("Nothing selected")
          : QString("%1 %2: not in the scene (any more)").arg(Q(sel.kind), Q(sel.name)));
  if (sel.kind.empty()) {
    auto* hint =
        new QLabel("Pick in the Scene Renderer or select a body or tendon in the tree.", form_);
    hint->setWordWrap(true);
    form_layout_->addWidget(hint);
  }
}

void SelectionPanel::BuildBody(const BodyInfo& body) {
  title_->setText("Body " + Q(body.name) + (body.moving ? "" : " (static)"));
  const std::string name = body.name;
  if (body.moving) {
    auto* row = new QHBoxLayout;
    row->addWidget(new QLabel("Mass", form_));
    mass_ = Spin("selection_mass", 0, 1, 4, " kg");
    row->addWidget(mass_, 1);
    auto* apply = Button("Apply", "apply_mass", form_);
    apply->setToolTip("set_mass: the inertia scales with the mass");
    row->addWidget(apply);
    form_layout_->addLayout(row);
    mass_id_ = scene_.daq_name + "." + body.name + ".mass";
    connect(apply, &QPushButton::clicked, this, [this, name] {
      link_.SetMass(name, mass_->value());
      Say(QString("setting the mass of %1 to %2 kg ...").arg(Q(name)).arg(mass_->value()));
    });
  }
  if (body.shapes.empty()) {
    form_layout_->addWidget(new QLabel("no collision shapes", form_));
    return;
  }
  auto* grid = new QGridLayout;
  grid->addWidget(new QLabel("Shapes (dimensions [m])", form_), 0, 0, 1, 4);
  for (unsigned k = 0; k < body.shapes.size(); ++k) {
    const ShapeInfo& shape = body.shapes[k];
    const int row = static_cast<int>(k) + 1;
    auto* label = new QLabel(QString("%1 %2").arg(k).arg(Q(shape.kind)), form_);
    label->setToolTip(Q(shape.name));
    grid->addWidget(label, row, 0);
    auto* dims = new QHBoxLayout;
    std::vector<QDoubleSpinBox*> spins;
    for (size_t d = 0; d < shape.dims.size(); ++d) {
      auto* spin = Spin(QString("shape_%1_dim_%2").arg(k).arg(d), shape.dims[d], 1, 4, " m");
      spins.push_back(spin);
      dims->addWidget(spin);
    }
    grid->addLayout(dims, row, 1);
    auto* apply = Button("Apply", QString("apply_shape_%1").arg(k), form_);
    apply->setEnabled(!spins.empty());
    grid->addWidget(apply, row, 2);
    connect(apply, &QPushButton::clicked, this, [this, name, k, spins] {
      std::vector<double> values;
      for (QDoubleSpinBox* spin : spins) values.push_back(spin->value());
      link_.SetShapeDims(name, k, values);
      Say(QString("setting shape %1 of %2 ...").arg(k).arg(Q(name)));
    });
  }
  form_layout_->addLayout(grid);
}

void SelectionPanel::BuildObstacle(const ObstacleInfo& obstacle) {
  title_->setText(QString("Obstacle %1 (%2 on %3)")
                      .arg(Q(obstacle.name), Q(obstacle.kind),
                           obstacle.body.empty() ? QString("the world") : Q(obstacle.body)));
  auto* form = new QFormLayout;
  auto* radius = Spin("obstacle_radius", obstacle.radius_m, 1, 4, " m");
  auto* length = Spin("obstacle_length", obstacle.length_m, 1, 4, " m");
  length->setEnabled(obstacle.kind != "sphere");
  form->addRow("Radius", radius);
  form->addRow("Length", length);
  QDoubleSpinBox* position[3];
  for (int a = 0; a < 3; ++a) {
    position[a] =
        Spin(QString("obstacle_%1").arg(kAxes[a]), obstacle.position_m[a], kMmPerM, 2, " mm");
    form->addRow(
        QString("%1 in %2").arg(kAxes[a], obstacle.body.empty() ? "world" : Q(obstacle.body)),
        position[a]);
  }
  form_layout_->addLayout(form);
  auto* row = new QHBoxLayout;
  auto* apply = Button("Apply", "apply_obstacle", form_);
  auto* remove = Button("Remove obstacle", "remove_obstacle", form_);
  row->addWidget(apply);
  row->addWidget(remove);
  form_layout_->addLayout(row);
  const ObstacleInfo base = obstacle;
  connect(apply, &QPushButton::clicked, this, [this, base, radius, length, position] {
    ObstacleInfo edited = base;  // kind, body and orientation stay
    edited.radius_m = radius->value();
    edited.length_m = length->value();
    for (int a = 0; a < 3; ++a) edited.position_m[a] = position[a]->value() / kMmPerM;
    link_.SetObstacle(edited);
    Say("moving and resizing obstacle " + Q(base.name) + " ...");
  });
  const std::string name = obstacle.name;
  connect(remove, &QPushButton::clicked, this, [this, name] {
    link_.RemoveObstacle(name);
    Say("removing obstacle " + Q(name) + " (Undo brings it back) ...");
  });
}

void SelectionPanel::BuildTendon(const TendonInfo& tendon, const Snapshot& s) {
  title_->setText(QString("Tendon %1 (radius %2 mm)")
                      .arg(Q(tendon.name))
                      .arg(tendon.radius_m * kMmPerM, 0, 'g', 6));
  QString path;
  for (unsigned k = 0; k < tendon.path.size(); ++k)
    path += QString("%1%2: %3").arg(k == 0 ? "" : "\n").arg(k).arg(ElementText(tendon.path[k]));
  QStringList actuators;
  for (const auto& a : s.scene.actuators)
    if (a.tendon == tendon.name) actuators << QString("%1 (%2)").arg(Q(a.name), Q(a.kind));
  auto* label = new QLabel(
      path + "\nactuators: " + (actuators.isEmpty() ? QString("none") : actuators.join(", ")),
      form_);
  label->setObjectName("tendon_path");
  label->setWordWrap(true);
  form_layout_->addWidget(label);
  auto* remove = Button("Remove tendon", "remove_tendon", form_);
  remove->setToolTip("removes the tendon with the actuators acting along it");
  form_layout_->addWidget(remove);
  const std::string name = tendon.name;
  connect(remove, &QPushButton::clicked, this, [this, name] {
    link_.RemoveTendon(name);
    Say("removing tendon " + Q(name) + " (Undo brings it back) ...");
  });
  // the tendon's channels and its actuators'
  std::vector<std::string> names = {tendon.name};
  for (const auto& a : s.scene.actuators)
    if (a.tendon == tendon.name) names.push_back(a.name);
  BuildSensorDelay(names, s);
}

void SelectionPanel::BuildSensorDelay(const std::vector<std::string>& names, const Snapshot& s) {
  const std::string undelayed = ".undelayed";
  const auto is_undelayed = [&](const std::string& id) {
    return id.size() > undelayed.size() &&
           id.compare(id.size() - undelayed.size(), std::string::npos, undelayed) == 0;
  };
  const std::map<std::string, double>& delays = scene_.sensor_delays_s;  // [s] by DAQ id
  auto* channel = new QComboBox(form_);
  channel->setObjectName("delay_channel");
  for (const Channel& c : s.channels) {
    if (!c.scalar() || c.writable || c.is_static || is_undelayed(c.id))
      continue;  // a sensor reads a changing state; not an id.undelayed
    const bool ours = std::any_of(names.begin(), names.end(), [&](const std::string& name) {
      return c.id.rfind(s.scene.daq_name + "." + name + ".", 0) == 0;
    });
    if (!ours) continue;
    const QString unit = c.unit.empty() ? QString() : " [" + Q(c.unit) + "]";
    const auto delay = delays.find(c.id);
    if (delay == delays.end()) {
      channel->addItem(Q(c.id) + unit, Q(c.id));
      continue;
    }
    const double delay_ms = delay->second * 1000;
    channel->addItem(Q(c.id) + unit + QString(" (%1 ms late)").arg(delay_ms, 0, 'g', 6), Q(c.id));
    channel->setItemData(channel->count() - 1, delay_ms, Qt::UserRole + 1);
    channel->setItemData(channel->count() - 1,
                         QString("reads %1 ms late (%2.undelayed is the true value); Apply sets "
                                 "another delay, 0 ms removes it")
                             .arg(delay_ms, 0, 'g', 6)
                             .arg(Q(c.id)),
                         Qt::ToolTipRole);
  }
  if (channel->count() == 0) {
    delete channel;
    return;
  }
  auto* row = new QHBoxLayout;
  row->addWidget(new QLabel("Sensor delay", form_));
  row->addWidget(channel, 1);
  QDoubleSpinBox* ms = Spin("delay_ms", 0, 1, 1, " ms");
  ms->setToolTip(
      "the channel reads its value this long ago, rounded to whole time steps (0 "
      "removes the delay; id.undelayed reads the true value)");
  // the chosen channel's delay now (0 without one)
  const auto show_delay = [channel, ms](int index) {
    ms->setValue(channel->itemData(index, Qt::UserRole + 1).toDouble());
  };
  show_delay(channel->currentIndex());
  connect(channel, QOverload<int>::of(&QComboBox::currentIndexChanged), ms, show_delay);
  row->addWidget(ms);
  auto* apply = Button("Apply", "apply_delay", form_);
  apply->setToolTip(
      "set_measurement_delay: for the controllers, the DAQ, the plotter and "
      "recordings (Undo removes it)");
  row->addWidget(apply);
  form_layout_->addLayout(row);
  connect(apply, &QPushButton::clicked, this, [this, channel, ms] {
    const std::string id = channel->currentData().toString().toStdString();
    link_.SetMeasurementDelay(id, ms->value() / 1000);
    Say(QString("delaying %1 by %2 ms ...").arg(Q(id)).arg(ms->value()));
  });
}

void SelectionPanel::BuildPathPoint(const TendonInfo& tendon, unsigned index) {
  const PathPointInfo& p = tendon.path[index];
  title_->setText(Q(PathElementName(tendon, index)));
  const std::string name = tendon.name;
  if (!p.obstacle.empty()) {
    form_layout_->addWidget(
        new QLabel("wraps around " + Q(p.obstacle) + ": move the obstacle to move it", form_));
  } else {
    auto* form = new QFormLayout;
    QDoubleSpinBox* position[3];
    const double values[3] = {p.x_m, p.y_m, p.z_m};
    for (int a = 0; a < 3; ++a) {
      position[a] = Spin(QString("point_%1").arg(kAxes[a]), values[a], kMmPerM, 2, " mm");
      form->addRow(QString("%1 in %2").arg(kAxes[a], p.body.empty() ? "world" : Q(p.body)),
                   position[a]);
    }
    form_layout_->addLayout(form);
    auto* apply = Button("Move", "apply_point", form_);
    apply->setToolTip("move_path_point: the point stays fixed in its body's frame");
    form_layout_->addWidget(apply);
    const PathPointInfo base = p;
    connect(apply, &QPushButton::clicked, this, [this, name, index, base, position] {
      PathPointInfo moved = base;
      moved.x_m = position[0]->value() / kMmPerM;
      moved.y_m = position[1]->value() / kMmPerM;
      moved.z_m = position[2]->value() / kMmPerM;
      link_.MovePathPoint(name, index, moved);
      Say(QString("moving point %1 of %2 to %3 ...").arg(index).arg(Q(name), Mm(moved)));
    });
  }
  auto* remove = Button("Remove via point", "remove_point", form_);
  remove->setToolTip("a tendon keeps at least its two ends");
  form_layout_->addWidget(remove);
  connect(remove, &QPushButton::clicked, this, [this, name, index] {
    link_.RemovePathPoint(name, index);
    Say(QString("removing point %1 of %2 ...").arg(index).arg(Q(name)));
  });
}

void SelectionPanel::UpdateValues(const Snapshot& s) {
  if (mass_ == nullptr || mass_id_.empty()) return;
  const auto v = s.values.find(mass_id_);
  if (v == s.values.end()) return;
  // the Model's value replaces what is shown unless the user is typing there
  if (v->second != shown_mass_ && !mass_->hasFocus()) {
    shown_mass_ = v->second;
    mass_->setValue(v->second);
  }
}

void SelectionPanel::OpenAddTendon() {
  if (scene_.bodies.empty()) {
    Say("add tendon: no scene is loaded");
    return;
  }
  const std::string from = selection_.kind == "body" ? selection_.name : std::string();
  auto* dialog = new AddTendonDialog(scene_, kinds_, from, this);
  dialog->setAttribute(Qt::WA_DeleteOnClose);
  connect(dialog, &QDialog::accepted, this, [this, dialog] {
    link_.AddTendon(dialog->tendon(), dialog->from(), dialog->to(), dialog->radius_m(),
                    dialog->actuator(), dialog->kind());
    Say("adding tendon " + Q(dialog->tendon()) + " ...");
  });
  dialog->show();
}

}  // namespace caliper::main_window
