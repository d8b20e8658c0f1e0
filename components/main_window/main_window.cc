#include "main_window.h"

#include <signal.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <QCloseEvent>
#include <QCoreApplication>
#include <QDateTime>
#include <QDir>
#include <QDockWidget>
#include <QDoubleSpinBox>
#include <QFileDialog>
#include <QFileInfo>
#include <QGuiApplication>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QMenu>
#include <QMenuBar>
#include <QProcess>
#include <QPushButton>
#include <QScreen>
#include <QScrollArea>
#include <QSettings>
#include <QSlider>
#include <QSpinBox>
#include <QStatusBar>
#include <QTimer>
#include <QTreeWidget>
#include <QVBoxLayout>
#include <QWindow>
#include <algorithm>
#include <memory>

#include "caliper/client/session.h"
#include "caliper/gui_session/tool_window.h"
#include "selection_panel.h"

namespace caliper::main_window {

namespace {

constexpr int kIdRole = Qt::UserRole;
constexpr int kGroupRole = Qt::UserRole + 2;  // a group row's dotted prefix
constexpr int kErrorShowMs = 8000;
// dragging the timeline sends at most one seek per period (a seek re-simulates up to a keyframe
// interval); the last position is always sent
constexpr int kSeekPeriodMs = 100;
constexpr unsigned kKeyframeEverySteps = 100;
const char* const kRecordingFilter = "Caliper recordings (*.caliper);;All files (*)";

QPushButton* Button(const QString& text, const char* name, QWidget* parent) {
  auto* b = new QPushButton(text, parent);
  b->setObjectName(name);
  return b;
}

QString Number(double v) { return QString::number(v, 'g', 7); }

// A tool's process: in a process group of its own (a terminal's Ctrl-C reaches the Main Window,
// which closes the tools in order and remembers them), and ended by the kernel when the Main
// Window dies without closing it.
class ToolProcess : public QProcess {
 public:
  using QProcess::QProcess;

 protected:
  void setupChildProcess() override {
    ::setpgid(0, 0);
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
  }
};

// the tools the Main Window opens: name, program, menu label
struct ToolSpec {
  const char* name;
  const char* program;
  const char* label;
};
constexpr ToolSpec kTools[] = {
    {"renderer", "caliper-renderer", "Scene &Renderer"},
    {"plotter", "caliper-plotter", "Graph &Plotter"},
    {"log_viewer", "caliper-logviewer", "&Log Viewer"},
};

const ToolSpec* FindTool(const QString& name) {
  for (const ToolSpec& t : kTools)
    if (name == t.name) return &t;
  return nullptr;
}

}  // namespace

MainWindow::MainWindow(std::unique_ptr<ModelLink> link, double refresh_hz, QWidget* parent,
                       bool restore_tools)
    : QMainWindow(parent), link_(std::move(link)) {
  setWindowTitle("Caliper");
  auto* central = new QWidget(this);
  auto* layout = new QVBoxLayout(central);
  BuildControls(central, layout);
  BuildTimeline(central, layout);
  BuildSettingsRow(central, layout);
  BuildNoModelRow(central, layout);
  BuildParameterTree(central, layout);
  setCentralWidget(central);

  QDockWidget* components_dock = BuildComponentsDock();
  BuildSelectionDock(components_dock);
  BuildFileAndEditMenus();
  BuildToolsMenu(components_dock);
  BuildStatusBar();
  ConnectControls();

  timer_ = new QTimer(this);
  connect(timer_, &QTimer::timeout, this, [this] { Refresh(); });
  timer_->start(static_cast<int>(1000.0 / std::max(refresh_hz, 0.1)));
  resize(1180, 760);
  RestoreSettings(restore_tools);
  Refresh();
}

void MainWindow::BuildControls(QWidget* central, QVBoxLayout* layout) {
  // simulation controls
  auto* controls = new QHBoxLayout;
  open_ = Button("Open model...", "open", central);
  start_ = Button("Start", "start", central);
  pause_ = Button("Pause", "pause", central);
  step_ = Button("Step", "step", central);
  step_count_ = new QSpinBox(central);
  step_count_->setObjectName("step_count");
  step_count_->setRange(1, 1000000);
  step_count_->setValue(1);
  step_count_->setToolTip("steps per Step");
  stop_ = Button("Stop", "stop", central);
  reset_ = Button("Reset", "reset", central);
  record_ = Button("Record", "record", central);
  record_->setCheckable(true);
  record_->setToolTip("record the session to a file in the Model's write directory");
  time_step_ = new QDoubleSpinBox(central);
  time_step_->setObjectName("time_step");
  time_step_->setDecimals(6);
  time_step_->setRange(1e-6, 1.0);
  time_step_->setSingleStep(0.0005);
  time_step_->setValue(0.001);
  time_step_->setSuffix(" s");
  real_time_factor_ = new QDoubleSpinBox(central);
  real_time_factor_->setObjectName("real_time_factor");
  real_time_factor_->setDecimals(2);
  real_time_factor_->setRange(0.0, 1000.0);
  real_time_factor_->setSingleStep(0.1);
  real_time_factor_->setValue(1.0);
  real_time_factor_->setSpecialValueText("max");
  real_time_factor_->setToolTip("real-time factor: 1 real time, 0 as fast as possible");
  for (QWidget* w :
       {static_cast<QWidget*>(open_), static_cast<QWidget*>(start_), static_cast<QWidget*>(pause_),
        static_cast<QWidget*>(step_), static_cast<QWidget*>(step_count_),
        static_cast<QWidget*>(stop_), static_cast<QWidget*>(reset_)})
    controls->addWidget(w);
  controls->addStretch();
  layout->addLayout(controls);
}

void MainWindow::BuildTimeline(QWidget* central, QVBoxLayout* layout) {
  // the replay's timeline: shown while the Model replays a recording
  timeline_ = new QWidget(central);
  timeline_->setObjectName("timeline");
  auto* timeline = new QHBoxLayout(timeline_);
  timeline->setContentsMargins(0, 0, 0, 0);
  timeline_file_ = new QLabel(timeline_);
  timeline_file_->setObjectName("timeline_file");
  timeline_file_->setMaximumWidth(220);
  timeline_slider_ = new QSlider(Qt::Horizontal, timeline_);
  timeline_slider_->setObjectName("timeline_slider");
  timeline_slider_->setToolTip("drag to seek in the recording");
  timeline_time_ = new QLabel(timeline_);
  timeline_time_->setObjectName("timeline_time");
  fork_ = Button("Fork", "fork", timeline_);
  fork_->setToolTip("leave the replay here: the Model simulates on, commands and edits allowed");
  timeline->addWidget(timeline_file_);
  timeline->addWidget(timeline_slider_, 1);
  timeline->addWidget(timeline_time_);
  timeline->addWidget(fork_);
  timeline_->hide();
  layout->addWidget(timeline_);
  seek_timer_ = new QTimer(this);
  seek_timer_->setSingleShot(true);
  seek_timer_->setInterval(kSeekPeriodMs);
}

void MainWindow::BuildSettingsRow(QWidget* central, QVBoxLayout* layout) {
  auto* settings = new QHBoxLayout;
  settings->addWidget(new QLabel("Time step", central));
  settings->addWidget(time_step_);
  settings->addSpacing(12);
  settings->addWidget(new QLabel("Real-time factor", central));
  settings->addWidget(real_time_factor_);
  // beside the speed rather than after Reset: the arranged window is too narrow for one more
  // button in the first row
  settings->addSpacing(12);
  settings->addWidget(record_);
  settings->addStretch();
  layout->addLayout(settings);
}

void MainWindow::BuildNoModelRow(QWidget* central, QVBoxLayout* layout) {
  no_model_ = new QLabel(central);
  no_model_->setObjectName("no_model");
  no_model_->setStyleSheet("QLabel { color: #b00020; font-weight: bold; }");
  no_model_->setWordWrap(true);
  start_model_ = Button("Start a Model", "start_model", central);
  start_model_->setToolTip("start caliper-model with the last model file");
  auto* no_model_row = new QHBoxLayout;
  no_model_row->addWidget(no_model_, 1);
  no_model_row->addWidget(start_model_);
  layout->addLayout(no_model_row);
}

void MainWindow::BuildParameterTree(QWidget* central, QVBoxLayout* layout) {
  // parameter browser
  tree_ = new QTreeWidget(central);
  tree_->setObjectName("parameters");
  tree_->setColumnCount(3);
  tree_->setHeaderLabels({"Parameter", "Value", "Unit"});
  tree_->setEditTriggers(QAbstractItemView::NoEditTriggers);
  // a tendon's selection shows its actuators' rows too
  tree_->setSelectionMode(QAbstractItemView::ExtendedSelection);
  tree_->header()->setSectionResizeMode(0, QHeaderView::Stretch);
  tree_->setColumnWidth(1, 160);
  tree_->header()->setStretchLastSection(false);
  tree_->setColumnWidth(2, 90);
  layout->addWidget(tree_);
}

QDockWidget* MainWindow::BuildComponentsDock() {
  // components panel: everything in the naming service with its lifecycle state
  auto* dock = new QDockWidget("Components", this);
  dock->setObjectName("components_dock");
  auto* panel = new QWidget(dock);
  auto* panel_layout = new QVBoxLayout(panel);
  components_ = new QTreeWidget(panel);
  components_->setObjectName("components");
  components_->setColumnCount(3);
  components_->setHeaderLabels({"Component", "State", "Path"});
  components_->setRootIsDecorated(false);
  components_->setSelectionMode(QAbstractItemView::SingleSelection);
  panel_layout->addWidget(components_);
  auto* actions = new QHBoxLayout;
  for (const char* verb : {"activate", "deactivate", "reset", "exit"}) {
    QString label = QString(verb);
    label[0] = label[0].toUpper();
    auto* b = Button(label, (std::string("component_") + verb).c_str(), panel);
    const std::string v = verb;
    connect(b, &QPushButton::clicked, this, [this, v] { SelectedComponentAction(v); });
    actions->addWidget(b);
  }
  panel_layout->addLayout(actions);
  dock->setWidget(panel);
  addDockWidget(Qt::BottomDockWidgetArea, dock);
  return dock;
}

void MainWindow::BuildSelectionDock(QDockWidget* components_dock) {
  // the selection shared with the renderer, and its edits
  auto* selection_dock = new QDockWidget("Selection", this);
  selection_dock->setObjectName("selection_dock");
  selection_panel_ = new SelectionPanel(*link_, selection_dock);
  selection_panel_->set_message_handler(
      [this](const QString& text) { statusBar()->showMessage(text, kErrorShowMs); });
  // scrolled: the panel's forms never widen the window beyond its session's geometry
  auto* selection_scroll = new QScrollArea(selection_dock);
  selection_scroll->setWidgetResizable(true);
  selection_scroll->setWidget(selection_panel_);
  selection_dock->setWidget(selection_scroll);
  // a tab beside the components: a narrow arranged window keeps its tree wide; a new
  // selection brings the tab up
  addDockWidget(Qt::BottomDockWidgetArea, selection_dock);
  tabifyDockWidget(components_dock, selection_dock);
  selection_dock_ = selection_dock;
}

void MainWindow::BuildFileAndEditMenus() {
  QMenu* file = menuBar()->addMenu("&File");
  open_recording_ = file->addAction("Open &recording...");
  open_recording_->setObjectName("open_recording");
  connect(open_recording_, &QAction::triggered, this, [this] { OpenRecording(); });

  QMenu* edit = menuBar()->addMenu("&Edit");
  undo_ = edit->addAction("&Undo");
  undo_->setObjectName("undo");
  undo_->setShortcuts(QKeySequence::Undo);
  undo_->setEnabled(false);
  redo_ = edit->addAction("&Redo");
  redo_->setObjectName("redo");
  redo_->setShortcuts({QKeySequence("Ctrl+Shift+Z"), QKeySequence("Ctrl+Y")});
  redo_->setEnabled(false);
  connect(undo_, &QAction::triggered, this, [this] {
    link_->Undo();
    statusBar()->showMessage("undoing ...", 3000);
  });
  connect(redo_, &QAction::triggered, this, [this] {
    link_->Redo();
    statusBar()->showMessage("redoing ...", 3000);
  });
  edit->addSeparator();
  QAction* add_tendon = edit->addAction("Add &tendon...");
  add_tendon->setObjectName("add_tendon_action");
  connect(add_tendon, &QAction::triggered, this, [this] { selection_panel_->OpenAddTendon(); });
  edit->addSeparator();
  edit->addAction(selection_dock_->toggleViewAction());
}

void MainWindow::BuildToolsMenu(QDockWidget* components_dock) {
  // menus: tools as their own processes, and the panels
  QMenu* tools = menuBar()->addMenu("&Tools");
  for (const ToolSpec& t : kTools) {
    QAction* action = tools->addAction(t.label);
    action->setObjectName(QString("tool_") + t.name);
    const QString name = t.name;
    connect(action, &QAction::triggered, this, [this, name] { StartTool(name); });
  }
  QAction* arrange = tools->addAction("&Arrange Windows");
  arrange->setObjectName("arrange_windows");
  connect(arrange, &QAction::triggered, this, [this] { ArrangeWindows(); });
  tools->addSeparator();
  QAction* model = tools->addAction("Start a &Model...");
  model->setObjectName("tool_model");
  connect(model, &QAction::triggered, this, [this] { StartModel(); });
  tools->addSeparator();
  tools->addAction(components_dock->toggleViewAction());
}

void MainWindow::BuildStatusBar() {
  recording_ = new QLabel(this);
  recording_->setObjectName("recording");
  statusBar()->addPermanentWidget(recording_);
  state_ = new QLabel(this);
  state_->setObjectName("state");
  sim_time_ = new QLabel(this);
  sim_time_->setObjectName("sim_time");
  steps_ = new QLabel(this);
  steps_->setObjectName("steps");
  achieved_ = new QLabel(this);
  achieved_->setObjectName("achieved_rtf");
  for (QLabel* l : {state_, sim_time_, steps_, achieved_}) statusBar()->addPermanentWidget(l);
}

void MainWindow::ConnectControls() {
  connect(open_, &QPushButton::clicked, this, [this] { OpenModelFile(); });
  connect(start_model_, &QPushButton::clicked, this, [this] { StartModel(); });
  connect(start_, &QPushButton::clicked, this, [this] { link_->Start(); });
  connect(pause_, &QPushButton::clicked, this, [this] { link_->Pause(); });
  connect(step_, &QPushButton::clicked, this,
          [this] { link_->Step(static_cast<unsigned>(step_count_->value())); });
  connect(stop_, &QPushButton::clicked, this, [this] { link_->Stop(); });
  connect(reset_, &QPushButton::clicked, this, [this] { link_->Reset(); });
  connect(record_, &QPushButton::clicked, this, [this](bool on) { ToggleRecording(on); });
  connect(fork_, &QPushButton::clicked, this, [this] {
    link_->Fork();
    statusBar()->showMessage("forking ...", 3000);
  });
  connect(timeline_slider_, &QSlider::valueChanged, this, [this](int value) {
    timeline_time_->setText(
        QString("%1 / %2 s").arg(TimelineTime(value), 0, 'f', 3).arg(replay_.end_time, 0, 'f', 3));
    if (!moving_slider_) RequestSeek(TimelineTime(value));
  });
  connect(seek_timer_, &QTimer::timeout, this, [this] {
    if (!seek_pending_) return;
    seek_pending_ = false;
    SendSeek(pending_seek_s_);
  });
  // editingFinished comes with every focus change too: only a changed step goes to the Model
  connect(time_step_, &QDoubleSpinBox::editingFinished, this, [this] {
    if (time_step_->value() != link_->snapshot().status.time_step)
      link_->SetTimeStep(time_step_->value());
  });
  connect(real_time_factor_, &QDoubleSpinBox::editingFinished, this,
          [this] { link_->SetRealTimeFactor(real_time_factor_->value()); });
  connect(tree_, &QTreeWidget::itemDoubleClicked, this, [this](QTreeWidgetItem* item, int column) {
    if (column == 1 && (item->flags() & Qt::ItemIsEditable)) tree_->editItem(item, 1);
  });
  connect(tree_, &QTreeWidget::itemChanged, this,
          [this](QTreeWidgetItem* item, int column) { OnItemChanged(item, column); });
  connect(tree_, &QTreeWidget::currentItemChanged, this,
          [this](QTreeWidgetItem* item, QTreeWidgetItem*) { OnCurrentItemChanged(item); });
}

MainWindow::~MainWindow() {
  timer_->stop();
  // the tools and the Model started here end with the window
  std::vector<QProcess*> processes;
  for (auto& [name, p] : tools_) processes.push_back(p);
  if (model_process_ != nullptr) processes.push_back(model_process_);
  for (QProcess* p : processes) {
    p->disconnect();
    if (p->state() != QProcess::NotRunning) p->terminate();
  }
  for (QProcess* p : processes) {
    if (p->state() != QProcess::NotRunning && !p->waitForFinished(5000)) {
      p->kill();
      p->waitForFinished(2000);
    }
  }
  link_.reset();  // joins the worker
}

QString MainWindow::ModelFileFilter() {
  return "Model files (*.dae *.zae *.urdf);;COLLADA (*.dae *.zae);;URDF (*.urdf);;All files (*)";
}

QString MainWindow::SettingsPath() {
  const QByteArray env = qgetenv("CALIPER_MAIN_SETTINGS");
  if (!env.isEmpty()) return QString::fromLocal8Bit(env);
  return QSettings(QSettings::IniFormat, QSettings::UserScope, "caliper", "caliper-main")
      .fileName();
}

void MainWindow::SaveSettings() {
  QSettings st(SettingsPath(), QSettings::IniFormat);
  st.setValue("window/geometry", geometry());
  st.setValue("window/maximized", isMaximized());
  st.setValue("window/state", saveState());
  st.setValue("model/last", last_model_);
  st.setValue("simulation/time_step", time_step_->value());
  st.setValue("simulation/real_time_factor", real_time_factor_->value());
  st.setValue("tools/open", OpenTools());
  st.sync();
}

void MainWindow::RestoreSettings(bool restore_tools) {
  QSettings st(SettingsPath(), QSettings::IniFormat);
  const QRect rect = st.value("window/geometry").toRect();
  setGeometry(rect.isValid() ? rect : ArrangedGeometry("main"));  // the first time: its place
  if (st.value("window/maximized", false).toBool()) setWindowState(Qt::WindowMaximized);
  restoreState(st.value("window/state").toByteArray());
  last_model_ = st.value("model/last").toString();
  saved_time_step_ = st.value("simulation/time_step", 0.0).toDouble();
  saved_real_time_factor_ = st.value("simulation/real_time_factor", -1.0).toDouble();
  if (saved_time_step_ > 0) time_step_->setValue(saved_time_step_);
  if (saved_real_time_factor_ >= 0) real_time_factor_->setValue(saved_real_time_factor_);
  if (restore_tools) ReopenTools();
}

void MainWindow::closeEvent(QCloseEvent* event) {
  SaveSettings();
  QMainWindow::closeEvent(event);
}

void MainWindow::ReopenTools() {
  const QStringList open =
      QSettings(SettingsPath(), QSettings::IniFormat).value("tools/open").toStringList();
  for (const QString& tool : open) StartTool(tool);
}

QString MainWindow::BinPath(const QString& name) const {
  // caliper-main's own directory; $CALIPER_BIN_DIR first when set (the tests run elsewhere)
  const QByteArray env = qgetenv("CALIPER_BIN_DIR");
  if (!env.isEmpty()) return QDir(QString::fromLocal8Bit(env)).filePath(name);
  return QDir(QCoreApplication::applicationDirPath()).filePath(name);
}

QStringList MainWindow::NameserviceArgs() const {
  // the tools get the address this window chose (a component started without one would take a
  // stale $CALIPER_NAMESERVICE as it is)
  std::string ns = link_->options().nameservice;
  if (ns.empty()) ns = client::ChooseNamingAddress("").address;
  return {"--nameservice", QString::fromStdString(ns)};
}

QStringList MainWindow::OpenTools() const {
  QStringList open;
  for (const auto& [name, p] : tools_)
    if (p->state() != QProcess::NotRunning) open << name;
  return open;
}

QStringList MainWindow::ToolNames() {
  QStringList names;
  for (const ToolSpec& t : kTools) names << t.name;
  return names;
}

void MainWindow::SetToolArguments(const QString& name, const QStringList& arguments) {
  tool_arguments_[name] = arguments;
}

void MainWindow::ReportEnd(QProcess* process, const QString& what) {
  connect(process, QOverload<int, QProcess::ExitStatus>::of(&QProcess::finished), this,
          [this, what](int code, QProcess::ExitStatus status) {
            if (status == QProcess::CrashExit)
              ShowError(what + " crashed (see its output in the terminal or the session's files)");
            else if (code != 0)
              ShowError(what + " ended with exit code " + QString::number(code) +
                        " (see its output in the terminal or the session's files)");
            else
              statusBar()->showMessage(what + " closed", 3000);
          });
}

long long MainWindow::ToolPid(const QString& name) const {
  const auto it = tools_.find(name);
  if (it == tools_.end() || it->second->state() == QProcess::NotRunning) return 0;
  return it->second->processId();
}

bool MainWindow::StartTool(const QString& name) {
  const auto it = tools_.find(name);
  if (it != tools_.end() && it->second->state() != QProcess::NotRunning) return true;
  const ToolSpec* spec = FindTool(name);
  if (spec == nullptr) {
    ShowError("unknown tool '" + name + "' (known: " + ToolNames().join(", ") + ")");
    return false;
  }
  const QString program = BinPath(spec->program);
  if (!QFileInfo(program).isExecutable()) {
    ShowError("no " + program);
    return false;
  }
  if (it != tools_.end()) {
    it->second->deleteLater();
    tools_.erase(it);
  }
  QStringList args = NameserviceArgs();
  if (name == "plotter") args << "--model" << QString::fromStdString(link_->options().instance);
  args << "--session" << SettingsPath();
  // a tool that has been open before restores its own geometry from the session file
  if (!gui_session::ReadToolWindow(SettingsPath(), name).geometry.isValid())
    args << "--geometry" << gui_session::FormatGeometry(ArrangedGeometry(name));
  args << tool_arguments_[name];
  const bool has_layout =
      QSettings(SettingsPath(), QSettings::IniFormat).contains("plotter/layout");
  if (name == "plotter" && !has_layout)
    for (const QString& plot : default_plots_) args << "--ids" << plot;
  auto* p = new ToolProcess(this);
  p->setProcessChannelMode(QProcess::ForwardedChannels);
  ReportEnd(p, name);
  p->start(program, args);
  if (!p->waitForStarted(3000)) {
    ShowError("could not start " + program + ": " + p->errorString());
    p->deleteLater();
    return false;
  }
  tools_[name] = p;
  statusBar()->showMessage("started " + name, 3000);
  return true;
}

QRect MainWindow::ArrangedGeometry(const QString& name) const {
  const QScreen* screen =
      this->screen() != nullptr ? this->screen() : QGuiApplication::primaryScreen();
  const QRect area = screen != nullptr ? screen->availableGeometry() : QRect(0, 0, 1280, 800);
  // left column: this window over the log viewer; right: the renderer over the plotter
  const int left_width =
      std::min(area.width() * 6 / 10, std::max(area.width() * 42 / 100, minimumSizeHint().width()));
  const int top_height = area.height() * 62 / 100;
  QRect cell;
  if (name == "main")
    cell = QRect(area.left(), area.top(), left_width, top_height);
  else if (name == "log_viewer")
    cell = QRect(area.left(), area.top() + top_height, left_width, area.height() - top_height);
  else if (name == "renderer")
    cell = QRect(area.left() + left_width, area.top(), area.width() - left_width, top_height);
  else
    cell = QRect(area.left() + left_width, area.top() + top_height, area.width() - left_width,
                 area.height() - top_height);
  // the window manager's frame (as measured on this window) goes around the client area
  const QRect frame = frameGeometry();
  const QRect client = geometry();
  return cell.adjusted(client.left() - frame.left(), client.top() - frame.top(),
                       client.right() - frame.right(), client.bottom() - frame.bottom());
}

void MainWindow::ArrangeWindows() {
  if (isMaximized()) showNormal();
  setGeometry(ArrangedGeometry("main"));
  QStringList moved;
  QStringList waiting;
  for (const auto& [name, process] : tools_) {
    if (process->state() != QProcess::Running) continue;
    const gui_session::ToolWindowRecord record = gui_session::ReadToolWindow(SettingsPath(), name);
    if (record.pid != process->processId() || record.window_id == 0) {
      waiting << name;  // started but not shown yet: it comes up in its place anyway
      continue;
    }
    std::unique_ptr<QWindow> window(QWindow::fromWinId(static_cast<WId>(record.window_id)));
    if (!window) {
      waiting << name;
      continue;
    }
    window->setGeometry(ArrangedGeometry(name));
    moved << name;
  }
  QString message = "arranged " + (QStringList("main window") + moved).join(", ");
  if (!waiting.isEmpty()) message += "; not shown yet: " + waiting.join(", ");
  statusBar()->showMessage(message, kErrorShowMs);
}

void MainWindow::StartModel(QString path) {
  if (model_process_ != nullptr && model_process_->state() != QProcess::NotRunning) {
    ShowError("a Model started here is still running");
    return;
  }
  if (path.isEmpty()) path = last_model_;
  if (path.isEmpty())
    path = QFileDialog::getOpenFileName(this, "Model file for the new Model", QString(),
                                        ModelFileFilter());
  if (path.isEmpty()) return;
  const QString program = BinPath("caliper-model");
  if (!QFileInfo(program).isExecutable()) {
    ShowError("no " + program);
    return;
  }
  path = QFileInfo(path).absoluteFilePath();
  if (model_process_ != nullptr) model_process_->deleteLater();
  model_process_ = new QProcess(this);
  model_process_->setProcessChannelMode(QProcess::ForwardedChannels);
  ReportEnd(model_process_, "the Model started here");
  QStringList args = {"-o", "model.scene=" + path, "-o", "exec.auto_activate=true"};
  args << NameserviceArgs();
  model_process_->start(program, args);
  if (!model_process_->waitForStarted(3000)) {
    ShowError("could not start caliper-model: " + model_process_->errorString());
    return;
  }
  last_model_ = path;
  statusBar()->showMessage("starting a Model with " + path + " ...", kErrorShowMs);
}

void MainWindow::RefreshComponents(const Snapshot& s) {
  if (s.components_version == components_version_) return;
  components_version_ = s.components_version;
  QString selected;
  if (QTreeWidgetItem* item = components_->currentItem())
    selected = item->data(0, kIdRole).toString();
  // update the rows in place when the same components are listed: the selection stays
  bool same = components_->topLevelItemCount() == static_cast<int>(s.components.size());
  for (int k = 0; same && k < components_->topLevelItemCount(); ++k)
    same = components_->topLevelItem(k)->data(0, kIdRole).toString().toStdString() ==
           s.components[k].path;
  if (!same) components_->clear();
  for (size_t k = 0; k < s.components.size(); ++k) {
    const ComponentInfo& c = s.components[k];
    QTreeWidgetItem* item =
        same ? components_->topLevelItem(static_cast<int>(k)) : new QTreeWidgetItem(components_);
    item->setText(0, QString::fromStdString(c.instance));
    item->setText(1, QString::fromStdString(c.state));
    item->setText(2, QString::fromStdString(c.path));
    item->setData(0, kIdRole, QString::fromStdString(c.path));
    item->setForeground(1, QBrush(c.state == "ACTIVE"     ? QColor(0, 128, 0)
                                  : c.state == "INACTIVE" ? QColor(90, 90, 90)
                                                          : QColor(176, 0, 32)));
    if (!same && item->data(0, kIdRole).toString() == selected) components_->setCurrentItem(item);
  }
  if (!s.naming_reachable && components_->topLevelItemCount() == 0)
    components_->setToolTip("the naming service does not answer");
  else
    components_->setToolTip(QString());
}

void MainWindow::SelectedComponentAction(const std::string& verb) {
  QTreeWidgetItem* item = components_->currentItem();
  if (item == nullptr) {
    ShowError("select a component first");
    return;
  }
  link_->ComponentAction(item->data(0, kIdRole).toString().toStdString(), verb);
  statusBar()->showMessage(QString("%1 %2 ...").arg(QString::fromStdString(verb), item->text(0)),
                           3000);
}

void MainWindow::OpenModelFile() {
  const QString path =
      QFileDialog::getOpenFileName(this, "Open model", QString(), ModelFileFilter());
  if (path.isEmpty()) return;
  link_->LoadScene(path.toStdString());
  statusBar()->showMessage("loading " + path + " ...", kErrorShowMs);
}

namespace {

QString ChooseWithDialog(QWidget* parent, bool save, const QString& title,
                         const QString& suggested) {
  return save ? QFileDialog::getSaveFileName(parent, title, suggested, kRecordingFilter)
              : QFileDialog::getOpenFileName(parent, title, suggested, kRecordingFilter);
}

}  // namespace

void MainWindow::ToggleRecording(bool on) {
  const Snapshot s = link_->snapshot();
  if (!on) {
    link_->StopRecording();
    record_mark_ = link_->snapshot().commands_queued;
    statusBar()->showMessage("stopping the recording ...", 3000);
    return;
  }
  record_->setChecked(false);  // checked when the Model says it records
  if (s.write_dir.empty()) {
    ShowError("the Model writes no files (its model.write_dir is empty): it cannot record");
    return;
  }
  const QString name =
      "session-" + QDateTime::currentDateTime().toString("yyyyMMdd-HHmmss") + ".caliper";
  const QString suggested = QDir(QString::fromStdString(s.write_dir)).filePath(name);
  const QString title = "Record to (a new file in the Model's write directory)";
  const QString path = choose_file_ ? choose_file_(true, title, suggested)
                                    : ChooseWithDialog(this, true, title, suggested);
  if (path.isEmpty()) return;
  link_->StartRecording(path.toStdString(), kKeyframeEverySteps);
  record_mark_ = link_->snapshot().commands_queued;
  statusBar()->showMessage("starting to record to " + path + " ...", 3000);
}

void MainWindow::OpenRecording() {
  const Snapshot s = link_->snapshot();
  const QString dir = QString::fromStdString(s.write_dir);
  const QString title = "Open recording";
  const QString path =
      choose_file_ ? choose_file_(false, title, dir) : ChooseWithDialog(this, false, title, dir);
  if (path.isEmpty()) return;
  link_->OpenReplay(path.toStdString());
  statusBar()->showMessage("opening " + path + " ...", kErrorShowMs);
}

double MainWindow::TimelineTime(int value) const {
  const ReplayInfo& r = replay_;
  if (r.last_step <= r.first_step) return r.start_time;
  const double dt = (r.end_time - r.start_time) / static_cast<double>(r.last_step - r.first_step);
  return r.start_time + value * dt;
}

void MainWindow::RequestSeek(double time_s) {
  if (seek_timer_->isActive()) {
    pending_seek_s_ = time_s;
    seek_pending_ = true;
    return;
  }
  SendSeek(time_s);
}

void MainWindow::SendSeek(double time_s) {
  link_->Seek(time_s);
  seek_mark_ = link_->snapshot().commands_queued;
  seek_timer_->start();
}

void MainWindow::RefreshRecording(const Snapshot& s) {
  const bool replaying = s.connected && s.replay.replaying;
  record_->setEnabled(s.connected && s.recordings && !replaying);
  time_step_->setEnabled(!replaying);  // a replay runs at its recording's step
  open_recording_->setEnabled(s.connected && s.recordings);
  // the button follows the Model once the last press was answered
  if (s.commands_done >= record_mark_ && record_->isChecked() != s.record.recording)
    record_->setChecked(s.connected && s.record.recording);

  const RecordInfo& r = s.record;
  const QString file = QFileInfo(QString::fromStdString(r.path)).fileName();
  if (s.connected && r.recording) {
    recording_->setStyleSheet("QLabel { color: #b00020; }");
    recording_->setText(QString("recording %1 (%2 MB, %3 s)")
                            .arg(file)
                            .arg(static_cast<double>(r.bytes) / 1e6, 0, 'f', 1)
                            .arg(static_cast<double>(r.steps) * s.status.time_step, 0, 'f', 1));
    recording_->setToolTip(QString::fromStdString(r.path));
  } else if (s.connected && !r.error.empty()) {
    recording_->setStyleSheet("QLabel { color: #b00020; font-weight: bold; }");
    recording_->setText(QString::fromStdString(r.error));
    recording_->setToolTip(QString::fromStdString(r.path));
  } else {
    recording_->clear();
    recording_->setToolTip(QString());
  }
  if (r.error != record_error_) {
    record_error_ = r.error;
    if (!r.error.empty()) ShowError(QString::fromStdString(r.error));
  }

  if (!replaying) {
    timeline_->hide();
    replay_ = ReplayInfo{};
    setWindowTitle("Caliper");
    return;
  }
  const ReplayInfo& p = s.replay;
  const QString name = QFileInfo(QString::fromStdString(p.path)).fileName();
  setWindowTitle("Caliper - replaying " + name);
  // elided: the row must leave room for the slider and Fork in a narrow window
  timeline_file_->setText(timeline_file_->fontMetrics().elidedText(
      "replaying " + name, Qt::ElideMiddle, timeline_file_->maximumWidth()));
  timeline_file_->setToolTip(QString::fromStdString(p.path));
  const bool changed = p.path != replay_.path || p.first_step != replay_.first_step ||
                       p.last_step != replay_.last_step;
  const std::uint64_t step = std::min(std::max(p.step, p.first_step), p.last_step);
  replay_ = p;
  moving_slider_ = true;
  if (changed) timeline_slider_->setRange(0, static_cast<int>(p.last_step - p.first_step));
  // the slider follows the replay unless the user holds it or a seek is on its way
  const bool seeking = seek_timer_->isActive() || seek_pending_ || s.commands_done < seek_mark_;
  if (changed || (!timeline_slider_->isSliderDown() && !seeking))
    timeline_slider_->setValue(static_cast<int>(step - p.first_step));
  moving_slider_ = false;
  timeline_time_->setText(QString("%1 / %2 s")
                              .arg(TimelineTime(timeline_slider_->value()), 0, 'f', 3)
                              .arg(p.end_time, 0, 'f', 3));
  timeline_->show();
}

void MainWindow::ShowError(const QString& message) {
  statusBar()->showMessage(message, kErrorShowMs);
}

QTreeWidgetItem* MainWindow::ItemOf(const std::string& id) const {
  const auto it = items_.find(id);
  return it == items_.end() ? nullptr : it->second;
}

QTreeWidgetItem* MainWindow::GroupOf(const std::string& prefix) const {
  const auto it = groups_.find(prefix);
  return it == groups_.end() ? nullptr : it->second;
}

void MainWindow::RefreshEditActions(const Snapshot& s) {
  const bool on = s.connected && s.editing;
  const QString undo = on ? QString::fromStdString(s.edit.undo) : QString();
  const QString redo = on ? QString::fromStdString(s.edit.redo) : QString();
  // "Undo set the mass of forearm to 1.3 kg": the Model's words for the edit
  undo_->setText(undo.isEmpty() ? QString("&Undo") : "&Undo " + undo);
  redo_->setText(redo.isEmpty() ? QString("&Redo") : "&Redo " + redo);
  undo_->setEnabled(!undo.isEmpty());
  redo_->setEnabled(!redo.isEmpty());
}

std::pair<std::string, std::string> MainWindow::EntityOf(const QTreeWidgetItem* item) const {
  if (item == nullptr || scene_name_.empty()) return {};
  const std::string prefix = item->data(0, kGroupRole).toString().toStdString();
  const std::string head = scene_name_ + ".";
  if (prefix.compare(0, head.size(), head) != 0) return {};
  std::string rest = prefix.substr(head.size());
  const SceneInfo& scene = link_->snapshot().scene;
  // a tendon's states live under <tendon>.tendon (tendons often share their actuator's name)
  const std::string suffix = ".tendon";
  if (rest.size() > suffix.size() &&
      rest.compare(rest.size() - suffix.size(), suffix.size(), suffix) == 0 &&
      scene.FindTendon(rest.substr(0, rest.size() - suffix.size())) != nullptr)
    return {"tendon", rest.substr(0, rest.size() - suffix.size())};
  if (scene.FindBody(rest) != nullptr) return {"body", rest};
  for (const auto& a : scene.actuators)
    if (a.name == rest && scene.FindTendon(a.tendon) != nullptr) return {"tendon", a.tendon};
  if (scene.FindTendon(rest) != nullptr) return {"tendon", rest};
  for (const auto& c : scene.constraints)
    if (c == rest) return {"constraint", rest};
  return {};
}

void MainWindow::OnCurrentItemChanged(QTreeWidgetItem* item) {
  if (following_ || updating_ || item == nullptr) return;
  const auto [kind, name] = EntityOf(item);
  if (kind.empty()) return;
  link_->Select(kind, name);  // the renderer highlights it; the panel follows the Model
}

void MainWindow::FollowSelection(const Snapshot& s) {
  const SelectionInfo& sel = s.selection;
  const SceneInfo& scene = s.scene;
  const std::string head = scene.daq_name + ".";
  auto group = [&](const std::string& name) { return GroupOf(head + name); };
  QTreeWidgetItem* current = nullptr;
  std::vector<QTreeWidgetItem*> also;  // rows shown selected beside the current one
  QString text;
  const QString name = QString::fromStdString(sel.name);
  auto tendon_rows = [&](const std::string& tendon) {
    current = group(tendon + ".tendon");
    QStringList actuators;
    for (const auto& a : scene.actuators) {
      if (a.tendon != tendon) continue;
      actuators << QString::fromStdString(a.name);
      if (QTreeWidgetItem* row = group(a.name)) also.push_back(row);
    }
    if (current == nullptr && !also.empty()) current = also.front();
    return actuators.isEmpty() ? QString("no actuator") : "actuators " + actuators.join(", ");
  };
  if (sel.kind == "body") {
    current = group(sel.name);
    const BodyInfo* b = scene.FindBody(sel.name);
    text = "selected body " + name + (b != nullptr && !b->moving ? " (static)" : "");
  } else if (sel.kind == "tendon") {
    text = "selected tendon " + name + " (" + tendon_rows(sel.name) + ")";
  } else if (sel.kind == "path_point") {
    const TendonInfo* t = scene.FindTendon(sel.name);
    const QString where = t != nullptr && sel.index < t->path.size()
                              ? QString::fromStdString(PathElementName(*t, sel.index))
                              : QString("point %1 of %2").arg(sel.index).arg(name);
    QString at;
    if (t != nullptr && sel.index < t->path.size() && t->path[sel.index].obstacle.empty()) {
      const PathPointInfo& p = t->path[sel.index];
      at = QString(" at (%1, %2, %3) mm in %4")
               .arg(p.x_m * 1000, 0, 'g', 6)
               .arg(p.y_m * 1000, 0, 'g', 6)
               .arg(p.z_m * 1000, 0, 'g', 6)
               .arg(p.body.empty() ? QString("the world") : QString::fromStdString(p.body));
    }
    text = "selected " + where + at + " (" + tendon_rows(sel.name) + ")";
  } else if (sel.kind == "obstacle") {
    // an obstacle has no parameters: its body's row is shown
    const ObstacleInfo* o = scene.FindObstacle(sel.name);
    if (o != nullptr) current = group(o->body);
    text = "selected obstacle " + name +
           (o != nullptr
                ? QString(" (%1 on %2, radius %3 mm)")
                      .arg(QString::fromStdString(o->kind),
                           o->body.empty() ? QString("the world") : QString::fromStdString(o->body))
                      .arg(o->radius_m * 1000, 0, 'g', 6)
                : QString());
  } else if (sel.kind == "constraint") {
    current = group(sel.name);
    text = "selected constraint " + name;
  } else {
    text = "nothing selected";
  }
  if (selection_shown_) statusBar()->showMessage(text, kErrorShowMs);
  selection_shown_ = true;

  // the row the user chose for this entity stays; otherwise the tree jumps to the entity's rows
  const auto chosen = EntityOf(tree_->currentItem());
  const std::string kind = sel.kind == "path_point" ? "tendon" : sel.kind;
  if (!sel.kind.empty() && chosen.first == kind && chosen.second == sel.name) return;
  following_ = true;
  tree_->clearSelection();
  for (QTreeWidgetItem* row : also) {
    row->setSelected(true);
    row->setExpanded(true);
  }
  if (current != nullptr) {
    for (QTreeWidgetItem* p = current->parent(); p != nullptr; p = p->parent())
      p->setExpanded(true);
    current->setExpanded(true);
    tree_->setCurrentItem(current, 0, QItemSelectionModel::Select);
    tree_->scrollToItem(current, QAbstractItemView::PositionAtTop);  // its parameters below
  }
  following_ = false;
}

void MainWindow::Refresh() {
  const Snapshot s = link_->snapshot();
  RefreshComponents(s);
  if (s.notice_serial != notice_serial_) {
    notice_serial_ = s.notice_serial;
    ShowError(QString::fromStdString(s.last_notice));
  }
  if (s.error_serial != error_serial_) {
    error_serial_ = s.error_serial;
    ShowError(QString::fromStdString(s.last_error));
  }

  no_model_->setVisible(!s.connected);
  start_model_->setVisible(!s.connected);
  start_model_->setEnabled(model_process_ == nullptr ||
                           model_process_->state() == QProcess::NotRunning);
  for (QWidget* w :
       {static_cast<QWidget*>(start_), static_cast<QWidget*>(pause_), static_cast<QWidget*>(step_),
        static_cast<QWidget*>(stop_), static_cast<QWidget*>(reset_), static_cast<QWidget*>(open_)})
    w->setEnabled(s.connected);
  RefreshEditActions(s);
  RefreshRecording(s);
  if (!s.connected) {
    const QString why = QString::fromStdString(s.connection_message);
    no_model_->setText(why);
    state_->setText("no Model");
    sim_time_->clear();
    steps_->clear();
    achieved_->clear();
    if (statusBar()->currentMessage().isEmpty()) statusBar()->showMessage(why, 1000);
    return;
  }

  const ModelStatus& st = s.status;
  if (!st.scene.empty()) last_model_ = QString::fromStdString(st.scene);
  if (!settings_applied_) {  // the saved simulation settings reach the first Model found
    settings_applied_ = true;
    if (saved_time_step_ > 0 && saved_time_step_ != st.time_step)
      link_->SetTimeStep(saved_time_step_);
    if (saved_real_time_factor_ >= 0 && saved_real_time_factor_ != st.real_time_factor)
      link_->SetRealTimeFactor(saved_real_time_factor_);
  }
  state_->setText(QString::fromStdString(st.state));
  sim_time_->setText(QString("t = %1 s").arg(st.sim_time, 0, 'f', 3));
  steps_->setText(QString("%1 steps").arg(static_cast<qulonglong>(st.steps)));
  achieved_->setText(QString("RTF %1").arg(st.achieved_real_time_factor, 0, 'f', 2));
  if (!st.last_error.empty()) state_->setToolTip(QString::fromStdString(st.last_error));
  if (!time_step_->hasFocus() && st.time_step > 0) time_step_->setValue(st.time_step);
  if (!real_time_factor_->hasFocus()) real_time_factor_->setValue(st.real_time_factor);

  if (s.channels_version != channels_version_) {
    channels_version_ = s.channels_version;
    BuildTree(s);
    selection_shown_ = false;  // the new rows follow the selection again, quietly
  }

  scene_name_ = s.scene.daq_name;
  if (s.scene_version != scene_version_ || s.selection.revision != selection_revision_ ||
      !selection_shown_) {
    const bool moved = s.selection.revision != selection_revision_;
    scene_version_ = s.scene_version;
    selection_revision_ = s.selection.revision;
    selection_panel_->Rebuild(s);
    if (moved && !s.selection.kind.empty()) selection_dock_->raise();
    if (moved || !selection_shown_) FollowSelection(s);
  }
  selection_panel_->UpdateValues(s);

  // live values of the scalars in expanded groups; those are the ones watched next
  updating_ = true;
  std::vector<std::string> visible;
  for (const auto& [id, item] : items_) {
    bool shown = true;
    for (QTreeWidgetItem* p = item->parent(); p != nullptr; p = p->parent())
      shown = shown && p->isExpanded();
    if (!shown || item->data(1, kIdRole + 1).toBool() == false) continue;  // not a scalar
    visible.push_back(id);
    const auto v = s.values.find(id);
    if (v != s.values.end() && !tree_->isPersistentEditorOpen(item, 1))
      item->setText(1, Number(v->second));
  }
  updating_ = false;
  for (const std::string& id : selection_panel_->watched())
    if (std::find(visible.begin(), visible.end(), id) == visible.end()) visible.push_back(id);
  link_->Watch(std::move(visible));
}

void MainWindow::BuildTree(const Snapshot& s) {
  updating_ = true;
  tree_->clear();
  items_.clear();
  groups_.clear();
  std::map<std::string, QTreeWidgetItem*>& groups = groups_;
  for (const Channel& c : s.channels) {
    QTreeWidgetItem* parent = nullptr;
    std::string prefix;
    size_t start = 0;
    for (size_t dot = c.id.find('.'); dot != std::string::npos; dot = c.id.find('.', start)) {
      const std::string part = c.id.substr(start, dot - start);
      prefix = c.id.substr(0, dot);
      QTreeWidgetItem*& g = groups[prefix];
      if (g == nullptr) {
        g = parent == nullptr ? new QTreeWidgetItem(tree_) : new QTreeWidgetItem(parent);
        g->setText(0, QString::fromStdString(part));
        g->setData(0, kGroupRole, QString::fromStdString(prefix));
        // selectable: choosing a body's or tendon's row selects it on the Model
        g->setFlags(Qt::ItemIsEnabled | Qt::ItemIsSelectable);
      }
      parent = g;
      start = dot + 1;
    }
    auto* item = parent == nullptr ? new QTreeWidgetItem(tree_) : new QTreeWidgetItem(parent);
    item->setText(0, QString::fromStdString(c.id.substr(start)));
    item->setData(0, kIdRole, QString::fromStdString(c.id));
    item->setData(1, kIdRole + 1, c.scalar());
    item->setText(2, QString::fromStdString(c.unit));
    item->setToolTip(
        0, QString::fromStdString(c.id + (c.description.empty() ? "" : ": ") + c.description));
    if (!c.scalar()) item->setText(1, QString("%1x%2").arg(c.rows).arg(c.cols));
    Qt::ItemFlags flags = Qt::ItemIsEnabled | Qt::ItemIsSelectable;
    if (c.writable && c.scalar()) {
      flags |= Qt::ItemIsEditable;
      item->setToolTip(1, "double-click to edit");
    } else {
      item->setForeground(1, QBrush(Qt::darkGray));
    }
    item->setFlags(flags);
    items_[c.id] = item;
  }
  tree_->expandAll();
  updating_ = false;
}

void MainWindow::OnItemChanged(QTreeWidgetItem* item, int column) {
  if (updating_ || column != 1) return;
  const std::string id = item->data(0, kIdRole).toString().toStdString();
  if (id.empty()) return;
  bool ok = false;
  const double value = item->text(1).trimmed().toDouble(&ok);
  if (!ok) {
    ShowError(QString("%1: '%2' is not a number").arg(QString::fromStdString(id), item->text(1)));
    return;  // the next refresh shows the Model's value again
  }
  link_->Set(id, value);
  statusBar()->showMessage(QString("set %1 = %2").arg(QString::fromStdString(id), Number(value)),
                           3000);
}

}  // namespace caliper::main_window
