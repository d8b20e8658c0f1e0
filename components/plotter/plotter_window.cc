#include "plotter_window.h"

#include <QAction>
#include <QApplication>
#include <QBuffer>
#include <QCheckBox>
#include <QCloseEvent>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFileDialog>
#include <QFileInfo>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QImage>
#include <QLabel>
#include <QLineEdit>
#include <QLocale>
#include <QMenuBar>
#include <QMessageBox>
#include <QPageSize>
#include <QPainter>
#include <QPdfWriter>
#include <QPrintDialog>
#include <QPrinter>
#include <QPushButton>
#include <QRegularExpression>
#include <QSettings>
#include <QSpinBox>
#include <QSplitter>
#include <QStatusBar>
#include <QSvgGenerator>
#include <QTimer>
#include <QToolBar>
#include <QTreeWidget>
#include <QVBoxLayout>
#include <algorithm>
#include <cmath>
#include <ostream>
#include <set>

#include <qwt_plot_renderer.h>
#include <qwt_scale_draw.h>
#include <qwt_scale_widget.h>

#include "caliper/core/system.h"
#include "csv_export.h"
#include "plot_view.h"

namespace caliper::plotter {

namespace {

using Clock = std::chrono::steady_clock;
constexpr int kKeyRole = Qt::UserRole;       // channels: the series key (or the whole id)
constexpr int kPlotRole = Qt::UserRole + 1;  // curves: the plot index
constexpr int kStatusEveryTicks = 8;
constexpr int kStatusMessageMs = 10000;

bool Contains(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

QString Grouped(unsigned long long n) { return QLocale(QLocale::English).toString(n); }

}  // namespace

PlotterWindow::PlotterWindow(std::unique_ptr<DaqLink> link, double frame_hz, QWidget* parent)
    : QMainWindow(parent), link_(std::move(link)) {
  setWindowTitle("Caliper Graph Plotter");
  BuildPlotArea(BuildSidePanel());
  BuildMenus(BuildToolBar());
  BuildStatusBar();

  NewPlot();
  UpdateTargets();
  RebuildCurves();
  UpdateBufferLimit();
  RefreshStatus();
  resize(1280, 800);

  timer_ = new QTimer(this);
  timer_->setInterval(std::max(1, static_cast<int>(1000.0 / std::max(1.0, frame_hz))));
  connect(timer_, &QTimer::timeout, this, [this] { Tick(); });
  timer_->start();
}

QWidget* PlotterWindow::BuildSidePanel() {
  // left: the Model's channels, the curves of each plot
  auto* side = new QWidget;
  auto* sv = new QVBoxLayout(side);
  sv->setContentsMargins(4, 4, 4, 4);
  BuildChannelList(sv);
  BuildCurveList(sv);
  return side;
}

void PlotterWindow::BuildChannelList(QVBoxLayout* sv) {
  search_ = new QLineEdit;
  search_->setObjectName("search");
  search_->setPlaceholderText("search ids: text, or a glob with * and ?");
  search_->setClearButtonEnabled(true);
  connect(search_, &QLineEdit::textChanged, this, [this] { FilterChannels(); });
  sv->addWidget(search_);
  channels_tree_ = new QTreeWidget;
  channels_tree_->setObjectName("channels");
  channels_tree_->setHeaderLabels({"id", "unit", "shape"});
  channels_tree_->setSelectionMode(QAbstractItemView::ExtendedSelection);
  channels_tree_->setRootIsDecorated(true);
  channels_tree_->header()->setSectionResizeMode(0, QHeaderView::Stretch);
  channels_tree_->header()->setSectionResizeMode(1, QHeaderView::ResizeToContents);
  channels_tree_->header()->setSectionResizeMode(2, QHeaderView::ResizeToContents);
  channels_tree_->header()->setStretchLastSection(false);
  channels_tree_->setTextElideMode(Qt::ElideLeft);  // the ends of ids tell them apart
  channels_tree_->setToolTip("Double click or Add: plot the selected ids in the target plot");
  connect(channels_tree_, &QTreeWidget::itemDoubleClicked, this, [this] { AddSelected(); });
  channels_tree_->setMinimumHeight(48);  // the window fits a small arranged cell
  sv->addWidget(channels_tree_, 3);
  auto* add_row = new QHBoxLayout;
  target_ = new QComboBox;
  target_->setObjectName("target_plot");
  add_ = new QPushButton("Add");
  add_->setObjectName("add");
  connect(add_, &QPushButton::clicked, this, [this] { AddSelected(); });
  add_row->addWidget(new QLabel("to"));
  add_row->addWidget(target_, 1);
  add_row->addWidget(add_);
  sv->addLayout(add_row);
}

void PlotterWindow::BuildCurveList(QVBoxLayout* sv) {
  curves_tree_ = new QTreeWidget;
  curves_tree_->setObjectName("curves");
  curves_tree_->setHeaderLabels({"curve", "style"});
  curves_tree_->header()->setSectionResizeMode(0, QHeaderView::Stretch);
  curves_tree_->header()->setSectionResizeMode(1, QHeaderView::ResizeToContents);
  curves_tree_->header()->setStretchLastSection(false);
  curves_tree_->setTextElideMode(Qt::ElideLeft);
  connect(curves_tree_, &QTreeWidget::itemSelectionChanged, this,
          [this] { CurveSelectionChanged(); });
  curves_tree_->setMinimumHeight(36);
  sv->addWidget(curves_tree_, 2);
  auto* curve_row = new QHBoxLayout;
  style_ = new QComboBox;
  style_->setObjectName("style");
  style_->addItems({"line", "scatter"});
  style_->setEnabled(false);
  plot_autoscale_ = new QCheckBox("autoscale");
  plot_autoscale_->setObjectName("plot_autoscale");
  plot_autoscale_->setToolTip("The value axis of the selected plot follows the data drawn");
  plot_autoscale_->setEnabled(false);
  remove_ = new QPushButton("Remove");
  remove_->setObjectName("remove");
  remove_->setEnabled(false);
  curve_row->addWidget(style_);
  curve_row->addWidget(plot_autoscale_);
  curve_row->addStretch(1);
  curve_row->addWidget(remove_);
  sv->addLayout(curve_row);
  connect(style_, QOverload<int>::of(&QComboBox::activated), this, [this](int index) {
    QTreeWidgetItem* item = curves_tree_->currentItem();
    if (item == nullptr || item->parent() == nullptr) return;
    const int p = item->data(0, kPlotRole).toInt();
    if (p < 0 || p >= plot_count()) return;
    plots_[static_cast<size_t>(p)]->SetStyle(item->text(0).toStdString(),
                                             index == 0 ? CurveStyle::kLine : CurveStyle::kScatter);
    LayoutChanged();
    Redraw();
  });
  connect(plot_autoscale_, &QCheckBox::clicked, this, [this](bool on) {
    QTreeWidgetItem* item = curves_tree_->currentItem();
    if (item == nullptr) return;
    const int p = item->data(0, kPlotRole).toInt();
    if (p < 0 || p >= plot_count()) return;
    PlotView* view = plots_[static_cast<size_t>(p)];
    if (!on) {
      const QwtInterval y = view->axisInterval(QwtPlot::yLeft);
      view->SetYRange(y.minValue(), y.maxValue());
    }
    view->SetAutoscale(on);
    LayoutChanged();
    Redraw(true);
  });
  connect(remove_, &QPushButton::clicked, this, [this] { RemoveSelected(); });
}

void PlotterWindow::BuildPlotArea(QWidget* side) {
  // right: the stacked plots
  plot_splitter_ = new QSplitter(Qt::Vertical);
  plot_splitter_->setObjectName("plots");
  plot_splitter_->setChildrenCollapsible(false);
  auto* main = new QSplitter(Qt::Horizontal);
  main->addWidget(side);
  main->addWidget(plot_splitter_);
  main->setStretchFactor(0, 0);
  main->setStretchFactor(1, 1);
  main->setSizes({420, 860});
  setCentralWidget(main);
}

std::vector<QAction*> PlotterWindow::BuildToolBar() {
  // tool bar and menus
  auto* tools = addToolBar("Plot");
  tools->setObjectName("toolbar");
  tools->setMovable(false);
  pause_ = tools->addAction("Pause");
  pause_->setObjectName("pause");
  pause_->setCheckable(true);
  pause_->setShortcut(Qt::Key_Space);
  pause_->setToolTip("Freeze the view (samples keep being recorded); again to follow live data");
  connect(pause_, &QAction::toggled, this, [this](bool on) { SetPaused(on); });
  QAction* clear = tools->addAction("Clear", this, [this] { Clear(); });
  clear->setObjectName("clear");
  clear->setToolTip("Drop every sample held (streaming goes on)");
  QAction* autoscale = tools->addAction("Autoscale", this, [this] { Autoscale(); });
  autoscale->setObjectName("autoscale");
  autoscale->setToolTip("Fit every value axis to the data drawn and keep following it");
  tools->addSeparator();
  AddBufferSettings(tools);
  tools->addSeparator();
  QAction* new_plot = tools->addAction("New plot", this, [this] {
    NewPlot();
    LayoutChanged();
    Redraw();
  });
  new_plot->setObjectName("new_plot");
  return {pause_, clear, autoscale, new_plot};
}

void PlotterWindow::AddBufferSettings(QToolBar* tools) {
  tools->addWidget(new QLabel(" window "));
  window_spin_ = new QDoubleSpinBox;
  window_spin_->setObjectName("window_s");
  window_spin_->setDecimals(3);
  window_spin_->setRange(kMinWindow, kMaxWindow);
  window_spin_->setValue(window_s_);
  window_spin_->setSuffix(" s");
  window_spin_->setToolTip("Span of simulated time drawn [s] (the buffer keeps more)");
  connect(window_spin_, &QDoubleSpinBox::editingFinished, this,
          [this] { SetWindow(window_spin_->value()); });
  tools->addWidget(window_spin_);
  tools->addWidget(new QLabel(" buffer "));
  buffer_spin_ = new QSpinBox;
  buffer_spin_->setObjectName("buffer_samples");
  buffer_spin_->setRange(static_cast<int>(kMinBuffer), static_cast<int>(MaxBufferSamples(0)));
  buffer_spin_->setSingleStep(100'000);
  buffer_spin_->setGroupSeparatorShown(true);
  buffer_spin_->setValue(static_cast<int>(store_.capacity()));
  buffer_spin_->setSuffix(" samples");
  buffer_spin_->setToolTip("Samples kept per curve: what CSV export writes (the oldest go first)");
  connect(buffer_spin_, &QSpinBox::editingFinished, this,
          [this] { SetBufferSamples(static_cast<size_t>(buffer_spin_->value())); });
  tools->addWidget(buffer_spin_);
  tools->addWidget(new QLabel(" every "));
  every_spin_ = new QSpinBox;
  every_spin_->setObjectName("every_n_steps");
  every_spin_->setRange(1, static_cast<int>(kMaxEveryNSteps));
  every_spin_->setValue(1);
  every_spin_->setSuffix(" steps");
  every_spin_->setToolTip("One sample every n simulation steps (the Model sends them in batches)");
  connect(every_spin_, &QSpinBox::editingFinished, this,
          [this] { SetEveryNSteps(static_cast<uint32_t>(every_spin_->value())); });
  tools->addWidget(every_spin_);
}

void PlotterWindow::BuildMenus(const std::vector<QAction*>& view_actions) {
  QMenu* file = menuBar()->addMenu("&File");
  file->addAction(
      "&Load layout...", this, [this] { LoadLayoutDialog(); }, QKeySequence::Open);
  file->addAction(
      "&Save layout...", this, [this] { SaveLayoutDialog(); }, QKeySequence::Save);
  file->addSeparator();
  file->addAction("Export &plot (PNG, SVG, PDF)...", this, [this] { ExportPlotDialog(); });
  file->addAction("Export &data (CSV)...", this, [this] { ExportCsvDialog(); });
  file->addAction(
      "P&rint...", this, [this] { PrintDialog(); }, QKeySequence::Print);
  file->addSeparator();
  file->addAction(
      "&Quit", this, [this] { close(); }, QKeySequence::Quit);
  QMenu* view = menuBar()->addMenu("&View");
  for (QAction* action : view_actions) view->addAction(action);
}

void PlotterWindow::BuildStatusBar() {
  connection_ = new QLabel;
  connection_->setObjectName("connection");
  rate_ = new QLabel;
  rate_->setObjectName("rate");
  held_ = new QLabel;
  held_->setObjectName("held");
  for (QLabel* label : {connection_, rate_, held_}) label->setContentsMargins(6, 0, 6, 0);
  statusBar()->addPermanentWidget(connection_, 1);
  statusBar()->addPermanentWidget(rate_);
  statusBar()->addPermanentWidget(held_);
}

PlotterWindow::~PlotterWindow() {
  // the widgets outlive the members: hiding the window moves the focus out of a spin box,
  // whose editingFinished must not reach a half-destroyed window
  timer_->stop();
  for (QObject* child : findChildren<QObject*>())
    QObject::disconnect(child, nullptr, this, nullptr);
  for (PlotView* p : plots_) p->on_user_time_range = nullptr;
}

PlotView* PlotterWindow::plot(int index) const {
  return index >= 0 && index < plot_count() ? plots_[static_cast<size_t>(index)] : nullptr;
}

PlotView* PlotterWindow::NewPlot() {
  auto* p = new PlotView;
  p->setObjectName(QString("plot%1").arg(plots_.size()));
  p->on_user_time_range = [this](double t0, double t1) { UserTimeRange(t0, t1); };
  plot_splitter_->addWidget(p);
  plots_.push_back(p);
  for (size_t k = 0; k < plots_.size(); ++k) plots_[k]->ShowTimeTitle(k + 1 == plots_.size());
  return p;
}

void PlotterWindow::RemovePlot(int index) {
  if (index < 0 || index >= plot_count()) return;
  RemovePlotView(index);
  DropUnusedSeries();
}

void PlotterWindow::RemovePlotView(int index) {
  delete plots_[static_cast<size_t>(index)];
  plots_.erase(plots_.begin() + index);
  for (size_t k = 0; k < plots_.size(); ++k) {
    plots_[k]->setObjectName(QString("plot%1").arg(k));
    plots_[k]->ShowTimeTitle(k + 1 == plots_.size());
  }
}

std::string PlotterWindow::UnitOf(const std::string& key) const {
  const std::string id = SplitKey(key).id;
  for (const auto& c : channels_)
    if (c.id == id) return c.unit;
  return "";
}

bool PlotterWindow::AddCurve(int plot, const std::string& key, CurveStyle style) {
  if (plot < 0 || plot > plot_count() || key.empty()) return false;
  if (store_.Find(key) < 0) {
    // one more series must fit the memory budget at the buffer's size
    const std::string problem = BufferBudgetProblem(store_.capacity(), store_.series_count() + 1);
    if (!problem.empty()) {
      ShowStatus(QString::fromStdString("cannot add " + key + ": " + problem +
                                        "; make the buffer smaller first"));
      return false;
    }
  }
  PlotView* p = plot == plot_count() ? NewPlot() : plots_[static_cast<size_t>(plot)];
  if (!p->AddCurve(CurveSpec{key, style, ""})) return false;
  if (store_.Find(key) < 0) {
    store_.AddSeries(key, UnitOf(key));
    ++series_epoch_;
  }
  LayoutChanged();
  Redraw();
  return true;
}

bool PlotterWindow::RemoveCurve(int plot, const std::string& key) {
  PlotView* p = this->plot(plot);
  if (p == nullptr || !p->RemoveCurve(key)) return false;
  DropUnusedSeries();
  LayoutChanged();
  Redraw();
  return true;
}

void PlotterWindow::DropUnusedSeries() {
  const std::vector<std::string> keys = CurrentLayout().Keys();
  for (size_t s = store_.series_count(); s-- > 0;) {
    const std::string key = store_.series(s).key;
    if (!Contains(keys, key)) {
      store_.RemoveSeries(key);
      ++series_epoch_;
    }
  }
}

void PlotterWindow::ApplyLayout(const Layout& layout) {
  applying_ = true;
  // new plots; the series of curves in both layouts keep their samples, the others go
  while (!plots_.empty()) RemovePlotView(plot_count() - 1);
  for (const PlotSpec& spec : layout.plots) {
    PlotView* p = NewPlot();
    p->SetYRange(spec.y_min, spec.y_max);
    p->SetAutoscale(spec.autoscale);
    for (const CurveSpec& c : spec.curves) p->AddCurve(c);
  }
  DropUnusedSeries();
  // the buffer within the memory budget for these curves; made smaller before new series come,
  // so that the buffers never take more than the budget meanwhile
  const std::vector<std::string> keys = CurrentLayout().Keys();
  size_t buffer = std::clamp(layout.buffer_samples, kMinBuffer, kMaxBuffer);
  const std::string problem = BufferBudgetProblem(buffer, keys.size());
  if (!problem.empty()) {
    buffer = MaxBufferSamples(keys.size());
    ShowStatus(QString::fromStdString(problem + ": the buffer keeps " + std::to_string(buffer) +
                                      " samples per curve"));
  }
  if (buffer < store_.capacity()) store_.SetCapacity(buffer);
  for (const std::string& key : keys)
    if (store_.Find(key) < 0) store_.AddSeries(key, UnitOf(key));
  store_.SetCapacity(buffer);
  ++series_epoch_;
  window_s_ = std::clamp(layout.window_s, kMinWindow, kMaxWindow);
  window_spin_->setValue(window_s_);
  UpdateBufferLimit();
  buffer_spin_->setValue(static_cast<int>(store_.capacity()));
  every_n_steps_ = std::clamp<uint32_t>(layout.every_n_steps, 1, kMaxEveryNSteps);
  every_spin_->setValue(static_cast<int>(every_n_steps_));
  applying_ = false;
  LayoutChanged();
  Redraw(true);
}

Layout PlotterWindow::CurrentLayout() const {
  Layout layout;
  for (const PlotView* p : plots_) layout.plots.push_back(p->spec());
  layout.window_s = window_s_;
  layout.buffer_samples = store_.capacity();
  layout.every_n_steps = every_n_steps_;
  return layout;
}

void PlotterWindow::UpdateWanted() {
  std::vector<std::string> ids;
  for (const auto& key : CurrentLayout().Keys()) {
    const std::string id = SplitKey(key).id;
    if (!Contains(ids, id)) ids.push_back(id);
  }
  link_->Want(ids, every_n_steps_);
}

void PlotterWindow::LayoutChanged() {
  if (applying_) return;
  UpdateBufferLimit();
  UpdateWanted();
  RebuildCurves();
  UpdateTargets();
  SaveLayoutToSession();
}

void PlotterWindow::UpdateBufferLimit() {
  const size_t curves = store_.series_count();
  const size_t most = MaxBufferSamples(curves);
  buffer_spin_->setMaximum(static_cast<int>(std::max(most, store_.capacity())));
  buffer_spin_->setToolTip(
      QString("Samples kept per curve: what CSV export writes (the oldest go first); at most %1 "
              "for %2 curve(s), as all buffers together take at most %3 MiB")
          .arg(Grouped(most))
          .arg(curves)
          .arg(kBufferBudgetBytes >> 20));
}

void PlotterWindow::UpdateTargets() {
  const int index = target_->currentIndex();
  target_->clear();
  for (int k = 0; k < plot_count(); ++k) target_->addItem(QString("Plot %1").arg(k + 1));
  target_->addItem("New plot");
  target_->setCurrentIndex(std::clamp(index, 0, target_->count() - 1));
}

void PlotterWindow::RebuildCurves() {
  curves_tree_->clear();
  for (int k = 0; k < plot_count(); ++k) {
    auto* top = new QTreeWidgetItem(curves_tree_, {QString("Plot %1").arg(k + 1), ""});
    top->setData(0, kPlotRole, k);
    for (const CurveSpec& c : plots_[static_cast<size_t>(k)]->spec().curves) {
      auto* child = new QTreeWidgetItem(top, {QString::fromStdString(c.key), Name(c.style)});
      child->setData(0, kPlotRole, k);
    }
  }
  curves_tree_->expandAll();
  CurveSelectionChanged();
}

void PlotterWindow::CurveSelectionChanged() {
  QTreeWidgetItem* item = curves_tree_->currentItem();
  const bool any = item != nullptr && item->isSelected();
  const bool curve = any && item->parent() != nullptr;
  style_->setEnabled(curve);
  remove_->setEnabled(any);
  plot_autoscale_->setEnabled(any);
  if (!any) return;
  const PlotView* p = plot(item->data(0, kPlotRole).toInt());
  if (p == nullptr) return;
  plot_autoscale_->setChecked(p->autoscale());
  if (curve) style_->setCurrentIndex(item->text(1) == "scatter" ? 1 : 0);
}

void PlotterWindow::RemoveSelected() {
  QTreeWidgetItem* item = curves_tree_->currentItem();
  if (item == nullptr) return;
  const int p = item->data(0, kPlotRole).toInt();
  if (item->parent() != nullptr) {
    RemoveCurve(p, item->text(0).toStdString());
  } else {
    RemovePlot(p);
    LayoutChanged();
    Redraw();
  }
}

void PlotterWindow::BuildChannels(const LinkStatus& s) {
  channels_tree_->clear();
  QList<QTreeWidgetItem*> items;
  for (const ChannelEntry& c : s.channels) {
    const QString id = QString::fromStdString(c.id);
    const QString unit = c.unit.empty() ? QString("-") : QString::fromStdString(c.unit);
    auto* item = new QTreeWidgetItem({id, unit, QString("%1x%2").arg(c.rows).arg(c.cols)});
    item->setData(0, kKeyRole, id);
    QString tip = QString::fromStdString(c.description);
    if (c.is_static) tip += (tip.isEmpty() ? "" : " ") + QString("(a parameter)");
    const std::string why = WhyNotPlottable(c);
    if (!why.empty()) tip += (tip.isEmpty() ? "" : "\n") + QString::fromStdString(why);
    if (!tip.isEmpty()) item->setToolTip(0, tip);
    const size_t n = static_cast<size_t>(c.rows) * c.cols;
    if (n > 1 && n <= kMaxElementCurves) {
      const bool vector = c.rows == 1 || c.cols == 1;
      for (unsigned r = 0; r < (vector ? 1u : c.rows); ++r) {
        for (unsigned k = 0; k < (vector ? n : c.cols); ++k) {
          const QString suffix =
              vector ? QString("[%1]").arg(k) : QString("[%1][%2]").arg(r).arg(k);
          auto* child = new QTreeWidgetItem(item, {suffix, unit, ""});
          child->setData(0, kKeyRole, id + suffix);
        }
      }
    }
    items << item;
  }
  channels_tree_->addTopLevelItems(items);
  FilterChannels();
}

void PlotterWindow::FilterChannels() {
  const QString text = search_->text().trimmed();
  const bool glob = text.contains('*') || text.contains('?');
  const QRegularExpression re(
      glob ? QRegularExpression::wildcardToRegularExpression(text) : QString(),
      QRegularExpression::CaseInsensitiveOption);
  for (int k = 0; k < channels_tree_->topLevelItemCount(); ++k) {
    QTreeWidgetItem* item = channels_tree_->topLevelItem(k);
    const QString id = item->text(0);
    const bool match =
        text.isEmpty() || (glob ? re.match(id).hasMatch() : id.contains(text, Qt::CaseInsensitive));
    item->setHidden(!match);
  }
}

void PlotterWindow::AddSelected() {
  std::vector<std::string> keys;
  QStringList refused;
  for (QTreeWidgetItem* item : channels_tree_->selectedItems()) {
    if (item->isHidden() || (item->parent() != nullptr && item->parent()->isHidden())) continue;
    if (item->childCount() > 0) {
      // a whole vector or matrix: each element, unless some of them are selected themselves
      bool some = false;
      for (int k = 0; k < item->childCount(); ++k) some |= item->child(k)->isSelected();
      if (!some)
        for (int k = 0; k < item->childCount(); ++k)
          keys.push_back(item->child(k)->data(0, kKeyRole).toString().toStdString());
      continue;
    }
    const std::string key = item->data(0, kKeyRole).toString().toStdString();
    const std::string id = SplitKey(key).id;
    const auto c = std::find_if(channels_.begin(), channels_.end(),
                                [&](const ChannelEntry& e) { return e.id == id; });
    // too large to offer element by element: say so
    if (item->parent() == nullptr && c != channels_.end() && c->rows * c->cols != 1) {
      const std::string why = WhyNotPlottable(*c);
      if (!why.empty()) refused << QString::fromStdString(why);
      continue;
    }
    keys.push_back(key);
  }
  if (!refused.isEmpty()) ShowStatus(refused.join("; "));
  if (keys.empty()) return;
  int target = std::min(target_->currentIndex(), plot_count());
  if (target < 0) target = plot_count();
  for (const auto& key : keys) {
    const bool new_plot = target == plot_count();
    AddCurve(target, key);
    if (new_plot && target < plot_count()) target_->setCurrentIndex(target);
  }
}

void PlotterWindow::Ingest(const ReceivedBatch& b) {
  if (!b.layout || b.times.empty()) return;
  if (mapped_layout_ != b.layout || mapped_series_epoch_ != series_epoch_) {
    // which value of a sample belongs to which series
    mapped_columns_.clear();
    mapped_ids_.clear();
    mapped_width_ = Width(*b.layout);
    for (size_t s = 0; s < store_.series_count(); ++s) {
      const KeyParts key = SplitKey(store_.series(s).key);
      for (const SubscribedId& id : *b.layout) {
        if (id.id != key.id) continue;
        const long offset = ElementOffset(key, id.rows, id.cols);
        if (offset >= 0) {
          mapped_columns_.push_back({s, id.offset + static_cast<size_t>(offset)});
          mapped_ids_.emplace_back(s, id.id);
          if (!id.unit.empty()) store_.SetUnit(s, id.unit);
        }
        break;
      }
    }
    mapped_layout_ = b.layout;
    mapped_series_epoch_ = series_epoch_;
  }
  // a batch laid out otherwise (shapes changed with a reload) cannot be read: counted, shown,
  // and the link lists the channels and subscribes anew
  if (b.values_per_sample != mapped_width_) {
    ++unreadable_batches_;
    link_->Resubscribe(b.subscription, "batches of " + std::to_string(b.values_per_sample) +
                                           " values per sample came for a layout of " +
                                           std::to_string(mapped_width_));
    return;
  }
  bool newly_stale = false;
  for (const auto& [s, id] : mapped_ids_) {
    const bool stale = Contains(b.stale_ids, id) || Contains(missing_, id);
    newly_stale |= stale && !store_.series(s).stale;
    store_.SetStale(s, stale);
  }
  if (newly_stale) link_->Relist();  // the scene changed: show its channels
  const auto r = store_.Append(b.times.data(), b.times.size(), b.data.data(), b.values_per_sample,
                               mapped_columns_);
  if (r.appended > 0) intake_.emplace_back(Clock::now(), r.appended);
}

void PlotterWindow::Tick() {
  for (const ReceivedBatch& b : link_->TakeBatches()) Ingest(b);
  if (++ticks_ % kStatusEveryTicks == 1) RefreshStatus();
  if (!paused_ && store_.version() != drawn_version_) Redraw();
}

double PlotterWindow::sample_rate() const {
  // samples per second between the oldest and the newest intake of the last two seconds
  const auto now = Clock::now();
  Clock::time_point oldest{}, newest{};
  size_t count = 0, entries = 0;
  for (const auto& [t, n] : intake_) {
    if (now - t > std::chrono::seconds(2)) continue;
    if (entries++ == 0)
      oldest = t;  // what came before it is not part of the span
    else
      count += n;
    newest = t;
  }
  if (entries < 2 || now - newest > std::chrono::seconds(1)) return 0.0;
  const double span = std::chrono::duration<double>(newest - oldest).count();
  return span > 0 ? static_cast<double>(count) / span : 0.0;
}

void PlotterWindow::RefreshStatus() {
  while (!intake_.empty() && Clock::now() - intake_.front().first > std::chrono::seconds(3))
    intake_.pop_front();
  const LinkStatus s = link_->status();
  if (s.channels_version != channels_version_) {
    channels_version_ = s.channels_version;
    channels_ = s.channels;
    BuildChannels(s);
    for (size_t k = 0; k < store_.series_count(); ++k) {
      const std::string unit = UnitOf(store_.series(k).key);
      if (!unit.empty()) store_.SetUnit(k, unit);
    }
  }
  missing_ = s.missing;
  if (s.connected) {
    // ids the Model lacks, and elements beyond an id's shape, get no values: stale
    for (size_t k = 0; k < store_.series_count(); ++k) {
      const KeyParts key = SplitKey(store_.series(k).key);
      const auto c = std::find_if(channels_.begin(), channels_.end(),
                                  [&](const ChannelEntry& e) { return e.id == key.id; });
      if (Contains(missing_, key.id) || c == channels_.end())
        store_.SetStale(k, true);
      else if (ElementOffset(key, c->rows, c->cols) < 0)
        store_.SetStale(k, true);
    }
  }
  QString text;
  const QString model = QString::fromStdString(s.instance);
  if (s.connected) {
    text = QString("connected to %1: %2, t = %3 s")
               .arg(model, QString::fromStdString(s.state))
               .arg(s.sim_time, 0, 'f', 3);
    if (!s.scene.empty()) text += ", " + QFileInfo(QString::fromStdString(s.scene)).fileName();
    if (!s.missing.empty()) text += QString(", %1 id(s) not in the Model").arg(s.missing.size());
  } else {
    text = QString("not connected to %1").arg(model);
  }
  if (!s.message.empty()) text += " - " + QString::fromStdString(s.message);
  connection_->setText(text);
  connection_->setToolTip(text);
  QString rate = QString("%1 samples/s").arg(Grouped(std::llround(sample_rate())));
  const uint64_t lost =
      s.batches_missing + s.batches_dropped + s.batches_discarded + s.consumer_failures;
  if (lost > 0) rate += QString(", %1 batches lost").arg(lost);
  if (unreadable_batches_ > 0)
    rate += QString(", %1 batches unreadable (ids changed shape)").arg(unreadable_batches_);
  if (paused_) rate += " - paused (view frozen, still recording)";
  rate_->setText(rate);
  held_->setText(
      QString("%1 of %2 samples held").arg(Grouped(store_.size()), Grouped(store_.capacity())));
}

void PlotterWindow::Redraw(bool fit_values) {
  double t0 = view_t0_, t1 = view_t1_;
  if (!paused_) {
    // a strip chart: the window fills from the first sample held, then scrolls with the newest
    const double first = store_.first_time();
    t1 = store_.last_time();
    t0 = t1 - window_s_;
    if (std::isnan(first)) {
      t0 = 0;
      t1 = window_s_;
    } else if (t0 < first) {
      t0 = first;
      t1 = first + window_s_;
    }
    fit_values = true;
  }
  for (PlotView* p : plots_) p->Draw(store_, t0, t1, fit_values);
  // one width for every value axis, so that the time axes line up
  int extent = 0;
  for (PlotView* p : plots_) {
    p->updateAxes();
    QwtScaleWidget* w = p->axisWidget(QwtPlot::yLeft);
    w->scaleDraw()->setMinimumExtent(0);
    extent = std::max(extent, static_cast<int>(std::ceil(w->scaleDraw()->extent(w->font()))));
  }
  for (PlotView* p : plots_) {
    QwtScaleWidget* w = p->axisWidget(QwtPlot::yLeft);
    w->scaleDraw()->setMinimumExtent(extent);
    p->updateLayout();
    p->replot();
    if (!paused_) p->ResetZoomBase();
  }
  drawn_version_ = store_.version();
}

void PlotterWindow::UserTimeRange(double t0, double t1) {
  view_t0_ = t0;
  view_t1_ = t1;
  if (!paused_) {
    paused_ = true;
    const QSignalBlocker block(pause_);
    pause_->setChecked(true);
    pause_->setText("Resume");
  }
  Redraw(false);
  RefreshStatus();
}

void PlotterWindow::SetPaused(bool paused) {
  if (paused != pause_->isChecked()) {
    const QSignalBlocker block(pause_);
    pause_->setChecked(paused);
  }
  pause_->setText(paused ? "Resume" : "Pause");
  if (paused == paused_) return;
  paused_ = paused;
  if (paused_) {
    // freeze what is shown
    if (!plots_.empty()) {
      const QwtInterval x = plots_.front()->axisInterval(QwtPlot::xBottom);
      view_t0_ = x.minValue();
      view_t1_ = x.maxValue();
    } else {
      view_t1_ = std::isnan(store_.last_time()) ? window_s_ : store_.last_time();
      view_t0_ = view_t1_ - window_s_;
    }
  } else {
    Redraw(true);
  }
  RefreshStatus();
}

void PlotterWindow::Clear() {
  store_.Clear();
  Redraw(false);
  RefreshStatus();
}

void PlotterWindow::Autoscale() {
  for (PlotView* p : plots_) p->SetAutoscale(true);
  Redraw(true);
  if (paused_)
    for (PlotView* p : plots_) p->ResetZoomBase();
  LayoutChanged();
}

void PlotterWindow::SetWindow(double seconds) {
  window_s_ = std::clamp(seconds, kMinWindow, kMaxWindow);
  if (window_spin_->value() != window_s_) window_spin_->setValue(window_s_);
  if (!paused_) Redraw(true);
  LayoutChanged();
}

void PlotterWindow::SetBufferSamples(size_t samples) {
  const std::string problem = BufferBudgetProblem(samples, store_.series_count());
  if (!problem.empty()) ShowStatus(QString::fromStdString(problem));
  samples = std::clamp(samples, kMinBuffer, MaxBufferSamples(store_.series_count()));
  if (samples != store_.capacity()) store_.SetCapacity(samples);
  if (buffer_spin_->value() != static_cast<int>(samples))
    buffer_spin_->setValue(static_cast<int>(samples));
  LayoutChanged();
  RefreshStatus();
}

void PlotterWindow::SetEveryNSteps(uint32_t n) {
  every_n_steps_ = std::clamp<uint32_t>(n, 1, kMaxEveryNSteps);
  if (every_spin_->value() != static_cast<int>(every_n_steps_))
    every_spin_->setValue(static_cast<int>(every_n_steps_));
  LayoutChanged();
}

void PlotterWindow::RenderPlots(QPainter* painter, const QRectF& target) {
  if (plots_.empty()) return;
  QwtPlotRenderer renderer;
  renderer.setDiscardFlag(QwtPlotRenderer::DiscardBackground, true);
  renderer.setDiscardFlag(QwtPlotRenderer::DiscardCanvasFrame, true);
  double total = 0;
  for (const PlotView* p : plots_) total += std::max(1, p->height());
  double y = target.top();
  for (PlotView* p : plots_) {
    const double h = target.height() * std::max(1, p->height()) / total;
    renderer.render(p, painter, QRectF(target.left(), y, target.width(), h));
    y += h;
  }
}

bool PlotterWindow::ExportPlot(const QString& path, QString* error) {
  const QString suffix = QFileInfo(path).suffix().toLower();
  if (suffix != "png" && suffix != "svg" && suffix != "pdf") {
    *error = "cannot export to '." + suffix + "': use .png, .svg or .pdf";
    return false;
  }
  QSize size = plot_splitter_->size();
  if (size.width() < 200 || size.height() < 100 * std::max(1, plot_count()))
    size = QSize(1000, 320 * std::max(1, plot_count()));
  const QRectF area(QPointF(0, 0), QSizeF(size));
  // drawn into memory, then written to a temporary file beside `path` that replaces it once
  // complete: a failed export leaves an existing file as it was (QSaveFile would take a short
  // write for a whole one)
  QBuffer drawing;
  drawing.open(QIODevice::WriteOnly);
  bool drawn = false;
  if (suffix == "png") {
    QImage image(size, QImage::Format_ARGB32);
    image.fill(Qt::white);
    QPainter painter(&image);
    RenderPlots(&painter, area);
    painter.end();
    drawn = image.save(&drawing, "PNG");
  } else if (suffix == "svg") {
    QSvgGenerator svg;
    svg.setOutputDevice(&drawing);
    svg.setSize(size);
    svg.setViewBox(QRect(QPoint(0, 0), size));
    svg.setTitle("Caliper Graph Plotter");
    QPainter painter;
    if (painter.begin(&svg)) {
      RenderPlots(&painter, area);
      drawn = painter.end();
    }
  } else {
    QPdfWriter pdf(&drawing);
    constexpr double kDpi = 96;
    pdf.setResolution(static_cast<int>(kDpi));
    pdf.setPageMargins(QMarginsF(0, 0, 0, 0));
    pdf.setPageSize(QPageSize(QSizeF(size.width() * 25.4 / kDpi, size.height() * 25.4 / kDpi),
                              QPageSize::Millimeter));
    pdf.setTitle("Caliper Graph Plotter");
    QPainter painter;
    if (painter.begin(&pdf)) {
      RenderPlots(&painter, QRectF(0, 0, pdf.width(), pdf.height()));
      drawn = painter.end();
    }
  }
  const QByteArray& bytes = drawing.data();
  if (!drawn || bytes.isEmpty()) {
    *error = "nothing was drawn for " + path;
    return false;
  }
  try {
    core::WriteFileReplacing(path.toStdString(), [&](std::ostream& out) {
      out.write(bytes.constData(), static_cast<std::streamsize>(bytes.size()));
    });
  } catch (const std::exception& e) {
    *error = QString::fromStdString(e.what());
    return false;
  }
  return true;
}

bool PlotterWindow::ExportCsv(const QString& path, QString* error) {
  std::vector<size_t> series;
  for (const auto& key : CurrentLayout().Keys()) {
    const long s = store_.Find(key);
    if (s >= 0) series.push_back(static_cast<size_t>(s));
  }
  try {
    ExportCsvFile(store_, series, path.toStdString());
  } catch (const std::exception& e) {
    *error = QString::fromStdString(e.what());
    return false;
  }
  return true;
}

void PlotterWindow::Print(QPrinter* printer) {
  QPainter painter;
  if (!painter.begin(printer)) return;
  const QRect page = printer->pageRect(QPrinter::DevicePixel).toRect();
  RenderPlots(&painter, QRectF(0, 0, page.width(), page.height()));
  painter.end();
}

bool PlotterWindow::SessionLayout(const QString& path, Layout* layout, QString* error) {
  if (path.isEmpty()) return false;
  QSettings st(path, QSettings::IniFormat);
  if (!st.contains("plotter/layout")) return false;
  try {
    *layout = ParseLayout(st.value("plotter/layout").toString().toStdString(),
                          path.toStdString() + " [plotter/layout]");
    return true;
  } catch (const LayoutError& e) {
    if (error != nullptr) *error = e.what();
    return false;
  }
}

bool PlotterWindow::RestoreSessionLayout(const QString& path, QString* error) {
  Layout layout;
  QString why;
  if (SessionLayout(path, &layout, &why)) {
    ApplyLayout(layout);
    return true;
  }
  if (why.isEmpty()) return false;  // the session holds no layout
  // keep the text before anything writes the session (closing writes the layout shown)
  QSettings st(path, QSettings::IniFormat);
  st.setValue("plotter/layout.rejected", st.value("plotter/layout"));
  st.sync();
  QString message = "the session's layout was not applied: " + why;
  message += st.status() == QSettings::NoError
                 ? " (kept as plotter/layout.rejected in " + path + ")"
                 : " (and it could not be kept as plotter/layout.rejected in " + path + ")";
  ShowSessionProblem(message);
  if (error != nullptr) *error = message;
  return false;
}

void PlotterWindow::SaveLayoutToSession() {
  if (session_file_.isEmpty() || applying_) return;
  QSettings st(session_file_, QSettings::IniFormat);
  st.setValue("plotter/layout", QString::fromStdString(FormatLayout(CurrentLayout())));
  st.sync();
}

void PlotterWindow::closeEvent(QCloseEvent* event) {
  SaveLayoutToSession();
  QMainWindow::closeEvent(event);
}

void PlotterWindow::ShowStatus(const QString& message) {
  statusBar()->showMessage(message, kStatusMessageMs);
}

void PlotterWindow::ShowSessionProblem(const QString& message) {
  // stays in the status line until another message, and a box once the window is up
  statusBar()->showMessage(message);
  QTimer::singleShot(0, this, [this, message] {
    auto* box =
        new QMessageBox(QMessageBox::Warning, "Graph Plotter", message, QMessageBox::Ok, this);
    box->setObjectName("session_problem");
    box->setAttribute(Qt::WA_DeleteOnClose);
    box->setModal(false);
    box->show();
  });
}

void PlotterWindow::ShowError(const QString& message) {
  statusBar()->showMessage(message, 10000);
  QMessageBox::warning(this, "Graph Plotter", message);
}

void PlotterWindow::ExportPlotDialog() {
  const QString path = QFileDialog::getSaveFileName(
      this, "Export the plot", "plot.png", "PNG image (*.png);;SVG drawing (*.svg);;PDF (*.pdf)");
  if (path.isEmpty()) return;
  QString error;
  if (!ExportPlot(path, &error))
    ShowError(error);
  else
    statusBar()->showMessage("wrote " + path, 5000);
}

void PlotterWindow::ExportCsvDialog() {
  const QString path =
      QFileDialog::getSaveFileName(this, "Export the data", "data.csv", "CSV (*.csv)");
  if (path.isEmpty()) return;
  QString error;
  if (!ExportCsv(path, &error))
    ShowError(error);
  else
    statusBar()->showMessage(QString("wrote %1 samples to %2").arg(store_.size()).arg(path), 5000);
}

void PlotterWindow::PrintDialog() {
  QPrinter printer(QPrinter::HighResolution);
  printer.setPageOrientation(QPageLayout::Landscape);
  QPrintDialog dialog(&printer, this);
  if (dialog.exec() != QDialog::Accepted) return;
  Print(&printer);
}

void PlotterWindow::SaveLayoutDialog() {
  const QString path = QFileDialog::getSaveFileName(this, "Save the layout", "plots.layout",
                                                    "Plotter layouts (*.layout);;All files (*)");
  if (path.isEmpty()) return;
  try {
    SaveLayout(CurrentLayout(), path.toStdString());
    statusBar()->showMessage("wrote " + path, 5000);
  } catch (const LayoutError& e) {
    ShowError(e.what());
  }
}

void PlotterWindow::LoadLayoutDialog() {
  const QString path = QFileDialog::getOpenFileName(this, "Load a layout", QString(),
                                                    "Plotter layouts (*.layout);;All files (*)");
  if (path.isEmpty()) return;
  try {
    ApplyLayout(LoadLayout(path.toStdString()));
  } catch (const LayoutError& e) {
    ShowError(e.what());
  }
}

}  // namespace caliper::plotter
