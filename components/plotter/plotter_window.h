#pragma once
// The Graph Plotter's window: the Model's DAQ channels with a search box, stacked plots sharing
// one time axis, live streaming with pause/resume and clear, exports (PNG, SVG, PDF, CSV),
// printing, layouts. The samples live in a SampleStore that a timer fills from the DaqLink's
// inbox; the plots only read it. No CORBA here.

#include <QMainWindow>
#include <QString>
#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "daq_link.h"
#include "plot_layout.h"
#include "sample_store.h"

class QAction;
class QCheckBox;
class QCloseEvent;
class QComboBox;
class QDoubleSpinBox;
class QLabel;
class QLineEdit;
class QPainter;
class QPrinter;
class QPushButton;
class QSpinBox;
class QSplitter;
class QTimer;
class QToolBar;
class QTreeWidget;
class QTreeWidgetItem;
class QVBoxLayout;

namespace caliper::plotter {

class PlotView;

/// The Graph Plotter's main window; owns the DaqLink and the SampleStore.
class PlotterWindow : public QMainWindow {
 public:
  /// Takes the link; `frame_hz` is how often received samples are taken in and drawn.
  explicit PlotterWindow(std::unique_ptr<DaqLink> link, double frame_hz = 30.0,
                         QWidget* parent = nullptr);
  ~PlotterWindow() override;

  /// Replaces the plots and settings with `layout`. The samples of curves in both layouts stay,
  /// those of curves it lacks go. A buffer too large for the memory budget is made smaller (the
  /// status line says so).
  void ApplyLayout(const Layout& layout);
  /// The plots and settings now.
  Layout CurrentLayout() const;
  /// Adds a curve for `key` to plot `plot` (plot_count() makes a new plot); false when that
  /// plot has it already, `plot` is out of range or one more curve would take the buffers past
  /// kBufferBudgetBytes (the status line says so).
  bool AddCurve(int plot, const std::string& key, CurveStyle style = CurveStyle::kLine);
  /// Removes a curve from a plot; false when it has none.
  bool RemoveCurve(int plot, const std::string& key);
  /// Number of stacked plots.
  int plot_count() const { return static_cast<int>(plots_.size()); }
  /// A plot, top first; nullptr when out of range.
  PlotView* plot(int index) const;

  /// Freezes the view (samples keep being recorded into the buffer) or follows the live data.
  void SetPaused(bool paused);
  /// Whether the view is frozen.
  bool paused() const { return paused_; }
  /// Drops every sample held (also while streaming).
  void Clear();
  /// Fits the value axes to the data drawn and turns autoscale on for every plot.
  void Autoscale();
  /// The span of simulated time drawn while live [s].
  void SetWindow(double seconds);
  /// Samples kept per curve (the oldest go first); shrinking keeps the newest. At most what the
  /// memory budget allows for the curves now (MaxBufferSamples; the status line says so).
  void SetBufferSamples(size_t samples);
  /// One sample every n simulation steps (subscribes anew).
  void SetEveryNSteps(uint32_t n);

  /// Writes the stacked plots to `path`: PNG, SVG or PDF by its suffix, whole or not at all (an
  /// existing file is replaced once the new one is complete). False with `error` set (naming
  /// the path and the reason) when the suffix is unknown or the file cannot be written.
  bool ExportPlot(const QString& path, QString* error);
  /// Writes every sample held as CSV (time, then one column per curve with its unit), whole or
  /// not at all as ExportPlot.
  bool ExportCsv(const QString& path, QString* error);
  /// Prints the stacked plots on `printer`, fitted to its page.
  void Print(QPrinter* printer);

  /// The session file (QSettings, INI) shared with the Main Window: the layout is written to
  /// `plotter/layout` whenever it changes and when the window closes. "" for none.
  void SetSessionFile(const QString& path) { session_file_ = path; }
  /// The layout stored in a session file; false when it has none (or it does not parse).
  static bool SessionLayout(const QString& path, Layout* layout, QString* error);
  /// Applies the layout stored in the session file `path`. One that does not parse is copied to
  /// `plotter/layout.rejected` in the session first (closing writes the layout shown over
  /// `plotter/layout`) and the reason is shown in the status line and a message; false then,
  /// with `error` set, and false when the session holds no layout.
  bool RestoreSessionLayout(const QString& path, QString* error);

  /// Takes in the received samples and redraws when there is something new (the timer calls it).
  void Tick();
  /// Shows the link's status now (Tick does every few frames).
  void RefreshStatus();

  /// The samples held.
  const SampleStore& store() const { return store_; }
  /// The connection to the Model.
  DaqLink& link() { return *link_; }
  /// Samples taken in per second of wall time, over the last two seconds.
  double sample_rate() const;
  /// Batches whose width did not fit their subscription's layout (dropped; the link subscribes
  /// anew).
  uint64_t unreadable_batches() const { return unreadable_batches_; }

 protected:
  void closeEvent(QCloseEvent* event) override;

 private:
  // the parts of the window, built in this order by the constructor
  QWidget* BuildSidePanel();  // the channel list and the curve list
  void BuildChannelList(QVBoxLayout* sv);
  void BuildCurveList(QVBoxLayout* sv);
  void BuildPlotArea(QWidget* side);
  std::vector<QAction*> BuildToolBar();     // returns the actions the View menu repeats
  void AddBufferSettings(QToolBar* tools);  // window span, buffer, every n steps
  void BuildMenus(const std::vector<QAction*>& view_actions);
  void BuildStatusBar();

  void BuildChannels(const LinkStatus& s);
  void FilterChannels();
  void AddSelected();
  void RebuildCurves();
  void CurveSelectionChanged();
  void RemoveSelected();
  void LayoutChanged();
  /// Draws every plot: the live window, or the frozen range while paused; `fit_values` fits the
  /// value axes (live: always).
  void Redraw(bool fit_values = false);
  void UpdateWanted();
  std::string UnitOf(const std::string& key) const;
  void RemovePlot(int index);
  void RemovePlotView(int index);
  void UpdateBufferLimit();
  void Ingest(const ReceivedBatch& b);
  void UserTimeRange(double t0, double t1);
  void DropUnusedSeries();
  void RenderPlots(QPainter* painter, const QRectF& target);
  PlotView* NewPlot();
  void UpdateTargets();
  void SaveLayoutToSession();
  void ExportPlotDialog();
  void ExportCsvDialog();
  void PrintDialog();
  void SaveLayoutDialog();
  void LoadLayoutDialog();
  void ShowError(const QString& message);
  void ShowStatus(const QString& message);
  void ShowSessionProblem(const QString& message);

  std::unique_ptr<DaqLink> link_;
  SampleStore store_;
  std::vector<PlotView*> plots_;
  double window_s_ = Layout::kDefaultWindow;
  uint32_t every_n_steps_ = 1;
  bool paused_ = false;
  double view_t0_ = 0;  // the frozen time range [s]
  double view_t1_ = 0;
  uint64_t drawn_version_ = ~uint64_t{0};
  uint64_t channels_version_ = 0;
  uint64_t ticks_ = 0;
  std::vector<ChannelEntry> channels_;
  std::vector<std::string> missing_;  // wanted ids the Model does not have
  // the columns of the last batch layout seen, for the series as they were then
  std::shared_ptr<const std::vector<SubscribedId>> mapped_layout_;
  uint64_t mapped_series_epoch_ = 0;
  uint64_t series_epoch_ = 1;
  std::vector<SampleStore::Column> mapped_columns_;
  std::vector<std::pair<size_t, std::string>> mapped_ids_;  // series -> its DAQ id
  size_t mapped_width_ = 0;
  uint64_t unreadable_batches_ = 0;
  std::deque<std::pair<std::chrono::steady_clock::time_point, size_t>> intake_;
  QString session_file_;
  bool applying_ = false;  // a layout is being applied: no session writes meanwhile

  QTimer* timer_ = nullptr;
  QLineEdit* search_ = nullptr;
  QTreeWidget* channels_tree_ = nullptr;
  QComboBox* target_ = nullptr;
  QPushButton* add_ = nullptr;
  QTreeWidget* curves_tree_ = nullptr;
  QComboBox* style_ = nullptr;
  QCheckBox* plot_autoscale_ = nullptr;
  QPushButton* remove_ = nullptr;
  QSplitter* plot_splitter_ = nullptr;
  QAction* pause_ = nullptr;
  QDoubleSpinBox* window_spin_ = nullptr;
  QSpinBox* buffer_spin_ = nullptr;
  QSpinBox* every_spin_ = nullptr;
  QLabel* connection_ = nullptr;
  QLabel* rate_ = nullptr;
  QLabel* held_ = nullptr;
};

}  // namespace caliper::plotter
