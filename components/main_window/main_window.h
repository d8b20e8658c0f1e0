#pragma once
// The Main Window: simulation controls, a status bar and the parameter browser. It only reads
// ModelLink snapshots (refreshed by a timer) and queues commands on it; it never calls CORBA.

#include <QMainWindow>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <utility>

#include "model_link.h"

class QAction;
class QCloseEvent;
class QDockWidget;
class QDoubleSpinBox;
class QProcess;
class QRect;
class QSettings;
class QSlider;
class QLabel;
class QPushButton;
class QSpinBox;
class QTimer;
class QTreeWidget;
class QTreeWidgetItem;
class QVBoxLayout;

namespace caliper::main_window {

class SelectionPanel;

class MainWindow : public QMainWindow {
 public:
  /// Takes the link; `refresh_hz` is how often the snapshot is shown.
  /// Restores the session from the settings file (SettingsPath()); `restore_tools` starts the
  /// tools that were open when it was saved.
  explicit MainWindow(std::unique_ptr<ModelLink> link, double refresh_hz = 5.0,
                      QWidget* parent = nullptr, bool restore_tools = true);
  ~MainWindow() override;

  ModelLink& link() { return *link_; }
  /// Shows the latest snapshot now (the timer calls it).
  void Refresh();
  /// The tree row of a channel id, or nullptr.
  QTreeWidgetItem* ItemOf(const std::string& id) const;
  /// The tree row grouping the ids that start with `prefix` + "." (e.g. ecce_arm.forearm), or
  /// nullptr.
  QTreeWidgetItem* GroupOf(const std::string& prefix) const;

  /// The file filter of the Open and Start-a-Model dialogs: every model file Caliper loads
  /// (COLLADA .dae and .zae, URDF .urdf) first, then each format, then all files.
  static QString ModelFileFilter();
  /// The per-user session file, or $CALIPER_MAIN_SETTINGS.
  static QString SettingsPath();
  /// Saves geometry, last model, simulation settings and open tools (closing does it too).
  void SaveSettings();
  const QString& last_model() const { return last_model_; }
  /// The tools the Main Window opens: renderer, plotter, log_viewer.
  static QStringList ToolNames();
  /// Starts a tool from caliper-main's bin directory as its own process, on the session file;
  /// a tool with no stored geometry is given its place in the arrangement.
  bool StartTool(const QString& name);
  /// Extra command line arguments for a tool, used whenever it starts.
  void SetToolArguments(const QString& name, const QStringList& arguments);
  /// What the plotter shows when the session holds no plot layout of its own: one entry per
  /// plot, each a comma-separated list of ids.
  void SetDefaultPlots(const QStringList& plots) { default_plots_ = plots; }
  /// Tiles the screen: this window and the log viewer on the left, the renderer and the
  /// plotter on the right. Running tools are moved through their native windows.
  void ArrangeWindows();
  /// Where `name` (a tool, or "main") goes in the arrangement, as the window's client area.
  QRect ArrangedGeometry(const QString& name) const;
  /// Starts caliper-model with `path` (the last model when empty; asks when there is none).
  void StartModel(QString path = QString());
  /// Starts the tools that were open when the session was saved.
  void ReopenTools();
  /// The names of the tools started here and still running.
  QStringList OpenTools() const;
  /// The process id of a running tool started here, 0 when there is none.
  long long ToolPid(const QString& name) const;

  /// Asks for a file: `save` for a new recording, else one to open; `suggested` is the
  /// directory or the proposed file. Returns "" when cancelled. The default shows a QFileDialog;
  /// tests set their own.
  using FileChooser =
      std::function<QString(bool save, const QString& title, const QString& suggested)>;
  void SetFileChooser(FileChooser chooser) { choose_file_ = std::move(chooser); }
  /// The Record button: starts a recording into a file chosen in the Model's write directory
  /// (`on`), or stops it.
  void ToggleRecording(bool on);
  /// File > Open recording...: the Model replays a chosen recording; the timeline appears.
  void OpenRecording();
  /// The timeline's time [s] at slider position `value`.
  double TimelineTime(int value) const;

 protected:
  void closeEvent(QCloseEvent* event) override;

 private:
  // the parts of the window, built in this order by the constructor
  void BuildControls(QWidget* central, QVBoxLayout* layout);
  void BuildTimeline(QWidget* central, QVBoxLayout* layout);
  void BuildSettingsRow(QWidget* central, QVBoxLayout* layout);
  void BuildNoModelRow(QWidget* central, QVBoxLayout* layout);
  void BuildParameterTree(QWidget* central, QVBoxLayout* layout);
  QDockWidget* BuildComponentsDock();
  void BuildSelectionDock(QDockWidget* components_dock);
  void BuildFileAndEditMenus();
  void BuildToolsMenu(QDockWidget* components_dock);
  void BuildStatusBar();
  /// Connects the controls, the timeline, the settings and the parameter tree.
  void ConnectControls();

  void BuildTree(const Snapshot& s);
  /// Edit menu: Undo and Redo named after what they would do, enabled when there is something.
  void RefreshEditActions(const Snapshot& s);
  /// The tree and the status bar follow the Model's selection.
  void FollowSelection(const Snapshot& s);
  /// The entity (kind, name) a tree group stands for: a body, a tendon (its node, or an
  /// actuator's), a constraint; empty when none.
  std::pair<std::string, std::string> EntityOf(const QTreeWidgetItem* item) const;
  void OnCurrentItemChanged(QTreeWidgetItem* item);
  void OnItemChanged(QTreeWidgetItem* item, int column);
  void OpenModelFile();
  void ShowError(const QString& message);
  void RestoreSettings(bool restore_tools);
  void RefreshComponents(const Snapshot& s);
  void SelectedComponentAction(const std::string& verb);
  QString BinPath(const QString& name) const;
  QStringList NameserviceArgs() const;
  /// Says in the status bar when `process` ends, and why when it failed.
  void ReportEnd(QProcess* process, const QString& what);
  /// The Record button, the recording's status label and the replay's timeline.
  void RefreshRecording(const Snapshot& s);
  /// Seeks to `time_s`, at most every kSeekPeriodMs; the last one asked for is always sent.
  void RequestSeek(double time_s);
  void SendSeek(double time_s);

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
  QPushButton* start_model_ = nullptr;
  QTreeWidget* components_ = nullptr;
  std::uint64_t components_version_ = 0;
  std::map<QString, QProcess*> tools_;             // tool name -> its process
  std::map<QString, QStringList> tool_arguments_;  // tool name -> extra arguments
  QStringList default_plots_;
  QProcess* model_process_ = nullptr;  // a Model started by "Start a Model"
  QString last_model_;
  bool settings_applied_ = false;  // saved simulation settings sent to the Model
  double saved_time_step_ = 0;
  double saved_real_time_factor_ = -1;
  QAction* undo_ = nullptr;
  QAction* redo_ = nullptr;
  SelectionPanel* selection_panel_ = nullptr;
  QDockWidget* selection_dock_ = nullptr;
  std::uint64_t scene_version_ = 0;
  std::uint64_t selection_revision_ = 0;
  bool selection_shown_ = false;                    // the Model's selection was followed once
  bool following_ = false;                          // the tree follows the Model's selection
  std::string scene_name_;  // the first part of the parameter ids (SceneInfo::daq_name)
  std::map<std::string, QTreeWidgetItem*> groups_;  // dotted prefix -> its group row
  std::map<std::string, QTreeWidgetItem*> items_;   // channel id -> its row
  std::uint64_t channels_version_ = 0;
  std::uint64_t error_serial_ = 0;
  std::uint64_t notice_serial_ = 0;
  bool updating_ = false;  // the tree is being filled, not edited
  FileChooser choose_file_;
  QPushButton* record_ = nullptr;
  QLabel* recording_ = nullptr;    // "recording FILE (N MB, T s)"
  std::uint64_t record_mark_ = 0;  // commands queued by the last Record press
  std::string record_error_;       // the recording error shown last
  QAction* open_recording_ = nullptr;
  QWidget* timeline_ = nullptr;  // the replay's row: file, slider, time, Fork
  QLabel* timeline_file_ = nullptr;
  QSlider* timeline_slider_ = nullptr;
  QLabel* timeline_time_ = nullptr;
  QPushButton* fork_ = nullptr;
  ReplayInfo replay_;             // the replay the timeline shows
  QTimer* seek_timer_ = nullptr;  // running: a seek went out less than kSeekPeriodMs ago
  bool seek_pending_ = false;     // a position waits for the timer
  double pending_seek_s_ = 0;
  std::uint64_t seek_mark_ = 0;  // commands queued by the last seek
  bool moving_slider_ = false;   // the slider follows the Model, not the user
};

}  // namespace caliper::main_window
