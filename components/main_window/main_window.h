#pragma once
// The Main Window: simulation controls, a status bar and the parameter browser. It only reads
// ModelLink snapshots (refreshed by a timer) and queues commands on it; it never calls CORBA.

#include <QMainWindow>
#include <cstdint>
#include <map>
#include <memory>
#include <string>

#include "model_link.h"

class QDoubleSpinBox;
class QLabel;
class QPushButton;
class QSpinBox;
class QTimer;
class QTreeWidget;
class QTreeWidgetItem;

namespace caliper::main_window {

class MainWindow : public QMainWindow {
 public:
  /// Takes the link; `refresh_hz` is how often the snapshot is shown.
  explicit MainWindow(std::unique_ptr<ModelLink> link, double refresh_hz = 5.0,
                      QWidget* parent = nullptr);
  ~MainWindow() override;

  ModelLink& link() { return *link_; }
  /// Shows the latest snapshot now (the timer calls it).
  void Refresh();
  /// The tree row of a channel id, or nullptr.
  QTreeWidgetItem* ItemOf(const std::string& id) const;

 private:
  void BuildTree(const Snapshot& s);
  void OnItemChanged(QTreeWidgetItem* item, int column);
  void OpenModelFile();
  void ShowError(const QString& message);

  std::unique_ptr<ModelLink> link_;
  QTimer* timer_ = nullptr;
  QPushButton* open_ = nullptr;
  QPushButton* start_ = nullptr;
  QPushButton* pause_ = nullptr;
  QPushButton* step_ = nullptr;
  QPushButton* stop_ = nullptr;
  QPushButton* reset_ = nullptr;
  QSpinBox* step_count_ = nullptr;
  QDoubleSpinBox* time_step_ = nullptr;
  QDoubleSpinBox* real_time_factor_ = nullptr;
  QLabel* no_model_ = nullptr;
  QLabel* state_ = nullptr;
  QLabel* sim_time_ = nullptr;
  QLabel* steps_ = nullptr;
  QLabel* achieved_ = nullptr;
  QTreeWidget* tree_ = nullptr;
  std::map<std::string, QTreeWidgetItem*> items_;   // channel id -> its row
  std::uint64_t channels_version_ = 0;
  std::uint64_t error_serial_ = 0;
  bool updating_ = false;                           // the tree is being filled, not edited
};

}  // namespace caliper::main_window
