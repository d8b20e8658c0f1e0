#include "log_viewer_window.h"

#include <QAction>
#include <QApplication>
#include <QCheckBox>
#include <QClipboard>
#include <QCloseEvent>
#include <QComboBox>
#include <QDateTime>
#include <QDateTimeEdit>
#include <QDir>
#include <QFileDialog>
#include <QFileInfo>
#include <QFont>
#include <QFontMetrics>
#include <QGridLayout>
#include <QGroupBox>
#include <QHeaderView>
#include <QItemSelectionModel>
#include <QKeyEvent>
#include <QLabel>
#include <QLineEdit>
#include <QMenuBar>
#include <QMessageBox>
#include <QScrollArea>
#include <QScrollBar>
#include <QSettings>
#include <QSplitter>
#include <QStatusBar>
#include <QTableView>
#include <QTimer>
#include <QToolBar>
#include <QTreeWidget>
#include <QVBoxLayout>
#include <algorithm>
#include <filesystem>
#include <stdexcept>
#include <system_error>

#include "caliper/core/system.h"
#include "session_file.h"

namespace caliper::log_viewer {

namespace {

constexpr int kPrefixRole = Qt::UserRole;  // a category node's dotted prefix, a component's name
constexpr const char* kGroup = "log_viewer";

struct PriorityChoice {
  const char* label;
  int priority;
};
constexpr PriorityChoice kPriorityChoices[] = {
    {"DEBUG (all)", logging::kDebug}, {"INFO", logging::kInfo},   {"NOTICE", logging::kNotice},
    {"WARN", logging::kWarn},         {"ERROR", logging::kError}, {"CRIT", logging::kCrit},
    {"ALERT", logging::kAlert},       {"FATAL", logging::kFatal}};

QComboBox* ModeCombo(const QString& name) {
  auto* combo = new QComboBox;
  combo->setObjectName(name);
  combo->addItem("Hide others", QString(ModeName(FilterMode::kHide)));
  combo->addItem("Highlight", QString(ModeName(FilterMode::kHighlight)));
  combo->setToolTip(
      "Hide the records that do not match, or show every record and highlight "
      "those that match");
  return combo;
}

FilterMode ModeOf(const QComboBox* combo) {
  FilterMode mode = FilterMode::kHide;
  ParseMode(combo->currentData().toString().toStdString(), &mode);
  return mode;
}

void SetMode(QComboBox* combo, FilterMode mode) {
  combo->setCurrentIndex(combo->findData(QString(ModeName(mode))));
}

QDateTimeEdit* TimeEdit(const QString& name) {
  auto* edit = new QDateTimeEdit(QDateTime::currentDateTime());
  edit->setObjectName(name);
  edit->setDisplayFormat("yyyy-MM-dd HH:mm:ss.zzz");
  edit->setCalendarPopup(true);
  edit->setEnabled(false);
  return edit;
}

int64_t MicrosOf(const QDateTimeEdit* edit) {
  return static_cast<int64_t>(edit->dateTime().toMSecsSinceEpoch()) * 1000;
}

void CollectUnchecked(const QTreeWidgetItem* node, std::set<std::string>* out) {
  for (int i = 0; i < node->childCount(); ++i) {
    const QTreeWidgetItem* child = node->child(i);
    const Qt::CheckState state = child->checkState(0);
    if (state == Qt::Unchecked)
      out->insert(child->data(0, kPrefixRole).toString().toStdString());
    else if (state == Qt::PartiallyChecked)
      CollectUnchecked(child, out);
  }
}

bool Covered(const std::string& category, const std::set<std::string>& excluded) {
  for (const auto& prefix : excluded)
    if (UnderCategory(category, prefix)) return true;
  return false;
}

QTreeWidgetItem* CheckableItem(QTreeWidgetItem* parent, const QString& text, const QString& key,
                               bool checked) {
  auto* item = new QTreeWidgetItem(parent, QStringList{text});
  item->setData(0, kPrefixRole, key);
  item->setFlags(Qt::ItemIsEnabled | Qt::ItemIsUserCheckable | Qt::ItemIsAutoTristate);
  item->setCheckState(0, checked ? Qt::Checked : Qt::Unchecked);
  return item;
}

}  // namespace

LogViewerWindow::LogViewerWindow(Options options, QWidget* parent)
    : QMainWindow(parent), options_(std::move(options)) {
  setWindowTitle("Caliper Log Viewer");
  model_ = new LogModel(this);

  table_ = new QTableView;
  table_->setObjectName("table");
  table_->setModel(model_);
  table_->setSelectionBehavior(QAbstractItemView::SelectRows);
  table_->setSelectionMode(QAbstractItemView::ExtendedSelection);
  table_->setWordWrap(false);
  table_->setShowGrid(false);
  table_->setAlternatingRowColors(true);
  table_->verticalHeader()->hide();
  // fixed row heights and column widths: nothing is measured over 100,000 rows
  table_->verticalHeader()->setSectionResizeMode(QHeaderView::Fixed);
  table_->verticalHeader()->setDefaultSectionSize(table_->fontMetrics().height() + 4);
  QHeaderView* header = table_->horizontalHeader();
  header->setSectionResizeMode(QHeaderView::Interactive);
  header->setStretchLastSection(true);
  QFont bold = table_->font();  // the severest rows are bold
  bold.setBold(true);
  const QFontMetrics metrics(bold);
  const int pad = 2 * metrics.averageCharWidth();
  const int ch = table_->fontMetrics().averageCharWidth();
  header->resizeSection(LogModel::kTimeColumn,
                        metrics.horizontalAdvance("00:00:00.000") + pad);
  header->resizeSection(LogModel::kPriorityColumn, metrics.horizontalAdvance("NOTICE") + pad);
  header->resizeSection(LogModel::kCategoryColumn, 18 * ch);
  header->resizeSection(LogModel::kComponentColumn, 11 * ch);
  header->resizeSection(LogModel::kHostColumn, 8 * ch);
  // the message right after who said it, so that a narrow window still shows it; category and
  // host last (copies and exports keep the model's order)
  header->moveSection(header->visualIndex(LogModel::kMessageColumn),
                      header->visualIndex(LogModel::kCategoryColumn));
  header->moveSection(header->visualIndex(LogModel::kComponentColumn),
                      header->visualIndex(LogModel::kMessageColumn));
  header->resizeSection(LogModel::kMessageColumn, 60 * ch);

  splitter_ = new QSplitter(Qt::Horizontal);
  splitter_->setObjectName("splitter");
  splitter_->addWidget(BuildFilterPanel());
  splitter_->addWidget(table_);
  splitter_->setStretchFactor(0, 0);
  splitter_->setStretchFactor(1, 1);
  splitter_->setSizes({320, 830});
  setCentralWidget(splitter_);

  connection_ = new QLabel;
  connection_->setObjectName("connection");
  problems_label_ = new QLabel;
  problems_label_->setObjectName("problems");
  problems_label_->setStyleSheet("color: #b00000");
  counts_ = new QLabel;
  counts_->setObjectName("counts");
  statusBar()->addWidget(connection_, 1);
  statusBar()->addWidget(problems_label_);
  statusBar()->addPermanentWidget(counts_);

  BuildMenus();

  poll_timer_ = new QTimer(this);
  connect(poll_timer_, &QTimer::timeout, this, [this] { Poll(); });
  apply_timer_ = new QTimer(this);
  apply_timer_->setSingleShot(true);
  connect(apply_timer_, &QTimer::timeout, this, [this] { ApplyFilters(); });
  save_timer_ = new QTimer(this);
  save_timer_->setSingleShot(true);
  connect(save_timer_, &QTimer::timeout, this, [this] { SaveSession(); });

  resize(1150, 650);
  tool_window_ =
      new gui_session::ToolWindow(this, kGroup, options_.session_file, options_.save_delay_ms);
  RestoreSession();
  tool_window_->Restore(options_.geometry);
  UpdateStatus();
  UpdateCounts();
}

LogViewerWindow::~LogViewerWindow() {
  poll_timer_->stop();
  link_.reset();  // unregisters the listener
}

QWidget* LogViewerWindow::BuildFilterPanel() {
  auto* panel = new QWidget;
  auto* layout = new QVBoxLayout(panel);
  layout->setContentsMargins(4, 4, 4, 4);
  layout->setSpacing(4);

  auto* priority_box = new QGroupBox("Priority");
  auto* pl = new QGridLayout(priority_box);
  priority_ = new QComboBox;
  priority_->setObjectName("priority");
  priority_->setToolTip("Records at least this severe match");
  for (const auto& c : kPriorityChoices) priority_->addItem(c.label, c.priority);
  priority_mode_ = ModeCombo("priority_mode");
  pl->addWidget(priority_, 0, 0);
  pl->addWidget(priority_mode_, 0, 1);
  layout->addWidget(priority_box);

  auto* text_box = new QGroupBox("Message text");
  auto* tl = new QGridLayout(text_box);
  text_ = new QLineEdit;
  text_->setObjectName("text");
  text_->setPlaceholderText("text or regular expression");
  text_->setClearButtonEnabled(true);
  regex_ = new QCheckBox("Regular expression");
  regex_->setObjectName("regex");
  const QString regex_help =
      QString(
          "A regular expression in RE2 syntax (no backreferences or lookaround, at most %1 "
          "bytes), searched in the whole message")
          .arg(logging::kMaxPatternBytes);
  regex_->setToolTip(regex_help);
  text_->setToolTip("Records whose message contains this text match.\n" + regex_help + ".");
  case_sensitive_ = new QCheckBox("Match case");
  case_sensitive_->setObjectName("case_sensitive");
  text_mode_ = ModeCombo("text_mode");
  text_error_ = new QLabel;
  text_error_->setObjectName("text_error");
  text_error_->setStyleSheet("color: #c00000");
  text_error_->setWordWrap(true);
  text_error_->hide();
  tl->addWidget(text_, 0, 0, 1, 2);
  tl->addWidget(regex_, 1, 0);
  tl->addWidget(case_sensitive_, 1, 1);
  tl->addWidget(text_mode_, 2, 1);
  tl->addWidget(text_error_, 3, 0, 1, 2);
  layout->addWidget(text_box);

  auto* time_box = new QGroupBox("Time");
  auto* ml = new QGridLayout(time_box);
  from_enabled_ = new QCheckBox("From");
  from_enabled_->setObjectName("from_enabled");
  to_enabled_ = new QCheckBox("To");
  to_enabled_->setObjectName("to_enabled");
  from_ = TimeEdit("from");
  to_ = TimeEdit("to");
  time_mode_ = ModeCombo("time_mode");
  ml->addWidget(from_enabled_, 0, 0);
  ml->addWidget(from_, 0, 1);
  ml->addWidget(to_enabled_, 1, 0);
  ml->addWidget(to_, 1, 1);
  ml->addWidget(time_mode_, 2, 1);
  layout->addWidget(time_box);

  auto* sources_box = new QGroupBox("Categories and components");
  auto* sl = new QGridLayout(sources_box);
  category_mode_ = ModeCombo("category_mode");
  component_mode_ = ModeCombo("component_mode");
  sl->addWidget(new QLabel("Categories"), 0, 0);
  sl->addWidget(category_mode_, 0, 1);
  sl->addWidget(new QLabel("Components"), 1, 0);
  sl->addWidget(component_mode_, 1, 1);
  layout->addWidget(sources_box);
  layout->addStretch(1);

  // the tree of categories and components, below the other filters
  sources_ = new QTreeWidget;
  sources_->setObjectName("sources");
  sources_->setHeaderLabel("Checked ones match");
  sources_->setMinimumHeight(4 * sources_->fontMetrics().height());
  sources_->setColumnCount(1);
  sources_->setSortingEnabled(true);
  sources_->sortByColumn(0, Qt::AscendingOrder);
  sources_->header()->setSortIndicatorShown(false);
  sources_->setToolTip(
      "Unchecked categories (with everything below them) and components "
      "do not match");
  categories_root_ = CheckableItem(sources_->invisibleRootItem(), "Categories", "", true);
  components_root_ = CheckableItem(sources_->invisibleRootItem(), "Components", "", true);
  // the filters scroll, the tree takes what is left: the window fits small screens
  auto* scroll = new QScrollArea;
  scroll->setWidget(panel);
  scroll->setWidgetResizable(true);
  scroll->setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
  scroll->setFrameShape(QFrame::NoFrame);
  scroll->setMinimumWidth(panel->minimumSizeHint().width() +
                          scroll->verticalScrollBar()->sizeHint().width());
  filter_splitter_ = new QSplitter(Qt::Vertical);
  filter_splitter_->setObjectName("filter_splitter");
  filter_splitter_->addWidget(scroll);
  filter_splitter_->addWidget(sources_);
  filter_splitter_->setStretchFactor(0, 0);
  filter_splitter_->setStretchFactor(1, 1);
  filter_splitter_->setCollapsible(0, false);
  filter_splitter_->setCollapsible(1, false);

  // every change applies at once, except typing, which waits for a pause
  auto now = [this] { ScheduleApply(0); };
  for (QComboBox* combo :
       {priority_, priority_mode_, text_mode_, time_mode_, category_mode_, component_mode_})
    connect(combo, QOverload<int>::of(&QComboBox::currentIndexChanged), this, now);
  connect(text_, &QLineEdit::textChanged, this, [this] { ScheduleApply(options_.text_delay_ms); });
  connect(text_, &QLineEdit::returnPressed, this, [this] { ApplyFilters(); });
  for (QCheckBox* box : {regex_, case_sensitive_}) connect(box, &QCheckBox::toggled, this, now);
  connect(from_enabled_, &QCheckBox::toggled, this, [this, now](bool on) {
    from_->setEnabled(on);
    now();
  });
  connect(to_enabled_, &QCheckBox::toggled, this, [this, now](bool on) {
    to_->setEnabled(on);
    now();
  });
  for (QDateTimeEdit* edit : {from_, to_})
    connect(edit, &QDateTimeEdit::dateTimeChanged, this, [this] {
      if (!updating_) ScheduleApply(options_.text_delay_ms);
    });
  connect(sources_, &QTreeWidget::itemChanged, this,
          [this](QTreeWidgetItem* item, int) { OnSourceChanged(item); });
  return filter_splitter_;
}

void LogViewerWindow::BuildMenus() {
  QMenu* file = menuBar()->addMenu("&File");
  QAction* open = file->addAction("&Open Session Log...", this, [this] { OpenFileDialog(); });
  open->setObjectName("open");
  open->setShortcut(QKeySequence::Open);
  QAction* live = file->addAction("Follow &Live Log", this, [this] { FollowLive(false); });
  live->setObjectName("follow_live");
  live->setShortcut(QKeySequence("Ctrl+L"));
  QAction* exp = file->addAction("&Export Selection...", this, [this] { ExportDialog(); });
  exp->setObjectName("export");
  exp->setShortcut(QKeySequence("Ctrl+E"));
  file->addSeparator();
  QAction* quit = file->addAction("&Close", this, [this] { close(); });
  quit->setShortcut(QKeySequence::Close);

  QMenu* edit = menuBar()->addMenu("&Edit");
  QAction* copy = edit->addAction("&Copy", this, [this] { CopySelection(); });
  copy->setObjectName("copy");
  copy->setShortcut(QKeySequence::Copy);
  // on the table, so that Ctrl+C there copies whole rows rather than the current cell
  copy->setShortcutContext(Qt::WidgetWithChildrenShortcut);
  table_->addAction(copy);
  table_->installEventFilter(this);
  QAction* all = edit->addAction("Select &All", table_, &QTableView::selectAll);
  all->setShortcut(QKeySequence::SelectAll);
  all->setShortcutContext(Qt::WidgetWithChildrenShortcut);
  table_->addAction(all);

  QMenu* view = menuBar()->addMenu("&View");
  follow_tail_ = view->addAction("Follow &Tail");
  follow_tail_->setObjectName("follow_tail");
  follow_tail_->setCheckable(true);
  follow_tail_->setChecked(true);
  follow_tail_->setShortcut(QKeySequence("Ctrl+T"));
  follow_tail_->setToolTip("Scroll to the newest record as records arrive");
  connect(follow_tail_, &QAction::toggled, this, [this](bool on) {
    if (on) table_->scrollToBottom();
    ScheduleSave();
  });
  show_filters_ = view->addAction("&Filters");
  show_filters_->setObjectName("show_filters");
  show_filters_->setCheckable(true);
  show_filters_->setChecked(true);
  show_filters_->setShortcut(QKeySequence("Ctrl+Shift+F"));
  show_filters_->setToolTip("Show or hide the filter panel (the filters stay in force)");
  connect(show_filters_, &QAction::toggled, this, [this](bool on) {
    splitter_->widget(0)->setVisible(on);
    ScheduleSave();
  });
  QAction* clear = view->addAction("&Clear Filters", this, [this] {
    FilterSettings cleared;
    cleared.mode = CurrentFilter().mode;  // the hide/highlight choices stay
    ShowFilter(cleared);
    ApplyFilters();
  });
  clear->setObjectName("clear_filters");
  clear->setToolTip("Every filter off (the hide or highlight choices stay)");

  QToolBar* bar = addToolBar("Log");
  bar->setObjectName("toolbar");
  bar->setMovable(false);
  bar->addAction(open);
  bar->addAction(live);
  bar->addAction(exp);
  bar->addAction(follow_tail_);
  bar->addAction(show_filters_);
  bar->addAction(clear);
}

// ---------------------------------------------------------------------------------------------
// sources: live service or file

void LogViewerWindow::FollowLive(bool keep) {
  if (link_) return;
  if (!keep) {
    file_.clear();
    problems_.clear();
    malformed_ = 0;
    ShowProblems();
    model_->Replace({});
    ResetSources();
  }
  link_ = std::make_unique<LogLink>(options_.link);
  poll_timer_->start(options_.poll_ms);
  setWindowTitle(QString("Caliper Log Viewer - live (%1)")
                     .arg(QString::fromStdString(options_.link.instance)));
  UpdateStatus();
  UpdateCounts();
}

bool LogViewerWindow::OpenFile(const QString& path, QString* error) {
  SessionFileContents contents;
  try {
    contents = ReadSessionFile(path.toStdString());
  } catch (const std::exception& e) {
    if (error != nullptr) *error = QString::fromStdString(e.what());
    statusBar()->showMessage(QString::fromStdString(e.what()), 10000);
    return false;
  }
  poll_timer_->stop();
  link_.reset();
  file_ = path;
  problems_.clear();
  for (const auto& p : contents.problems) problems_ << QString::fromStdString(p);
  if (contents.malformed > contents.problems.size())
    problems_ << QString("... %1 more malformed lines")
                     .arg(contents.malformed - contents.problems.size());
  malformed_ = contents.malformed;
  ShowProblems();
  model_->Replace(std::move(contents.records));
  ResetSources();
  UpdateSources();
  SetTimeDefaults();
  setWindowTitle(QString("Caliper Log Viewer - %1").arg(QFileInfo(path).fileName()));
  AfterAppend(1);
  UpdateStatus();
  UpdateCounts();
  return true;
}

void LogViewerWindow::ShowProblems() {
  QStringList shown;
  QStringList all;
  if (malformed_ > 0 && !problems_.isEmpty()) {
    // the full paths in the tooltip, the file's name on the status line
    QString first = problems_.front();
    first.replace(file_, QFileInfo(file_).fileName());
    shown << QString("%1 malformed line%2 skipped: %3")
                 .arg(malformed_)
                 .arg(malformed_ == 1 ? "" : "s")
                 .arg(first);
    all << problems_;
  }
  if (!session_problem_.isEmpty()) {
    shown << session_problem_;
    all << session_problem_;
  }
  problems_label_->setText(shown.join("; "));
  problems_label_->setToolTip(all.join('\n'));
}

void LogViewerWindow::Poll() {
  if (!link_) return;
  std::vector<logging::Record> records = link_->Take();
  if (!records.empty()) {
    const bool first = model_->store().empty();
    const size_t added = model_->Append(std::move(records));
    UpdateSources();
    if (first) SetTimeDefaults();
    AfterAppend(added);
  }
  UpdateStatus();
  UpdateCounts();
}

void LogViewerWindow::AfterAppend(size_t added) {
  if (added > 0 && follow_tail_->isChecked()) table_->scrollToBottom();
}

LinkStatus LogViewerWindow::link_status() const {
  if (!link_) return LinkStatus{false, "not following the live service", "", 0};
  return link_->status();
}

void LogViewerWindow::UpdateStatus() {
  QString text;
  QString colour = "#000000";
  if (link_) {
    const LinkStatus s = link_->status();
    if (s.connected) {
      text = QString("Live: connected - %1; session log %2")
                 .arg(QString::fromStdString(s.message), QString::fromStdString(s.session_file));
      colour = "#006000";
    } else {
      text = QString("Live: not connected - %1").arg(QString::fromStdString(s.message));
      colour = "#b00000";
    }
    if (s.lost > 0)
      text += QString("; %1 records missed (the logger no longer held them)").arg(s.lost);
    if (s.listener_failures > 0)
      text += QString("; %1 pushed batches not taken in (%2)")
                  .arg(s.listener_failures)
                  .arg(QString::fromStdString(s.listener_failure));
  } else if (!file_.isEmpty()) {
    text = QString("File: %1 (not live)").arg(QFileInfo(file_).fileName());
  } else {
    text = "No records: open a session log or follow the live log";
  }
  if (connection_->text() != text) {
    connection_->setText(text);
    connection_->setToolTip(file_.isEmpty() || link_ ? text : file_);
    connection_->setStyleSheet("color: " + colour);
  }
}

void LogViewerWindow::UpdateCounts() {
  const LogView& v = model_->view();
  QString text = QString("%1 of %2 records shown").arg(v.rows().size()).arg(model_->store().size());
  if (v.highlighted_count() > 0) text += QString(", %1 highlighted").arg(v.highlighted_count());
  counts_->setText(text);
}

void LogViewerWindow::SetTimeDefaults() {
  const RecordStore& store = model_->store();
  if (store.empty()) return;
  updating_ = true;
  if (!from_enabled_->isChecked())
    from_->setDateTime(QDateTime::fromMSecsSinceEpoch(store.entry(0).time_us / 1000));
  if (!to_enabled_->isChecked())
    to_->setDateTime(
        QDateTime::fromMSecsSinceEpoch(store.entry(store.size() - 1).time_us / 1000 + 1));
  updating_ = false;
}

// ---------------------------------------------------------------------------------------------
// the category and component tree

void LogViewerWindow::ResetSources() {
  updating_ = true;
  qDeleteAll(categories_root_->takeChildren());
  qDeleteAll(components_root_->takeChildren());
  category_items_.clear();
  component_items_.clear();
  categories_seen_ = 0;
  components_seen_ = 0;
  updating_ = false;
}

QTreeWidgetItem* LogViewerWindow::CategoryItem(const std::string& prefix) {
  auto it = category_items_.find(prefix);
  if (it != category_items_.end()) return it->second;
  const size_t dot = prefix.rfind('.');
  QTreeWidgetItem* parent =
      dot == std::string::npos ? categories_root_ : CategoryItem(prefix.substr(0, dot));
  const std::string name = dot == std::string::npos ? prefix : prefix.substr(dot + 1);
  QTreeWidgetItem* item =
      CheckableItem(parent, QString::fromStdString(name), QString::fromStdString(prefix),
                    !Covered(prefix, filter_.excluded_categories));
  category_items_[prefix] = item;
  return item;
}

void LogViewerWindow::UpdateSources() {
  const auto& categories = model_->store().categories();
  const auto& components = model_->store().components();
  if (categories_seen_ == categories.size() && components_seen_ == components.size()) return;
  updating_ = true;
  for (; categories_seen_ < categories.size(); ++categories_seen_)
    CategoryItem(categories[categories_seen_]);
  for (; components_seen_ < components.size(); ++components_seen_) {
    const std::string& name = components[components_seen_];
    component_items_[name] =
        CheckableItem(components_root_, QString::fromStdString(name.empty() ? "(none)" : name),
                      QString::fromStdString(name), filter_.excluded_components.count(name) == 0);
  }
  sources_->expandAll();
  updating_ = false;
}

void LogViewerWindow::OnSourceChanged(QTreeWidgetItem*) {
  if (!updating_) ScheduleApply(0);
}

// ---------------------------------------------------------------------------------------------
// filters

FilterSettings LogViewerWindow::CurrentFilter() const {
  FilterSettings s;
  s.max_priority = priority_->currentData().toInt();
  s.mode[kPriority] = ModeOf(priority_mode_);
  // unchecked nodes, and exclusions restored for categories not seen yet
  CollectUnchecked(categories_root_, &s.excluded_categories);
  for (const auto& prefix : filter_.excluded_categories)
    if (category_items_.count(prefix) == 0) s.excluded_categories.insert(prefix);
  s.mode[kCategory] = ModeOf(category_mode_);
  CollectUnchecked(components_root_, &s.excluded_components);
  for (const auto& name : filter_.excluded_components)
    if (component_items_.count(name) == 0) s.excluded_components.insert(name);
  s.mode[kComponent] = ModeOf(component_mode_);
  s.text = text_->text().toStdString();
  s.regex = regex_->isChecked();
  s.case_sensitive = case_sensitive_->isChecked();
  s.mode[kText] = ModeOf(text_mode_);
  s.from_time_us = from_enabled_->isChecked() ? MicrosOf(from_) : 0;
  // the edit shows milliseconds: `to` includes its whole millisecond
  s.to_time_us = to_enabled_->isChecked() ? MicrosOf(to_) + 999 : 0;
  s.mode[kTime] = ModeOf(time_mode_);
  return s;
}

void LogViewerWindow::ShowFilter(const FilterSettings& s) {
  updating_ = true;
  filter_ = s;
  int index = 0;
  for (int i = 0; i < priority_->count(); ++i)
    if (priority_->itemData(i).toInt() >= s.max_priority) index = i;
  priority_->setCurrentIndex(index);
  SetMode(priority_mode_, s.mode[kPriority]);
  text_->setText(QString::fromStdString(s.text));
  regex_->setChecked(s.regex);
  case_sensitive_->setChecked(s.case_sensitive);
  SetMode(text_mode_, s.mode[kText]);
  from_enabled_->setChecked(s.from_time_us != 0);
  if (s.from_time_us != 0)
    from_->setDateTime(QDateTime::fromMSecsSinceEpoch(s.from_time_us / 1000));
  to_enabled_->setChecked(s.to_time_us != 0);
  if (s.to_time_us != 0) to_->setDateTime(QDateTime::fromMSecsSinceEpoch(s.to_time_us / 1000));
  SetMode(time_mode_, s.mode[kTime]);
  SetMode(category_mode_, s.mode[kCategory]);
  SetMode(component_mode_, s.mode[kComponent]);
  // everything checked, then the exclusions (auto-tristate parents follow their children)
  categories_root_->setCheckState(0, Qt::Checked);
  for (const auto& prefix : s.excluded_categories) {
    auto it = category_items_.find(prefix);
    if (it != category_items_.end()) it->second->setCheckState(0, Qt::Unchecked);
  }
  components_root_->setCheckState(0, Qt::Checked);
  for (const auto& name : s.excluded_components) {
    auto it = component_items_.find(name);
    if (it != component_items_.end()) it->second->setCheckState(0, Qt::Unchecked);
  }
  updating_ = false;
}

void LogViewerWindow::ScheduleApply(int delay_ms) {
  if (updating_) return;
  apply_timer_->start(delay_ms);
}

void LogViewerWindow::ApplyFilters() {
  apply_timer_->stop();
  filter_ = CurrentFilter();
  if (filter_ != model_->view().settings()) {
    model_->SetFilter(filter_);
    if (follow_tail_->isChecked()) table_->scrollToBottom();
  }
  const QString error = QString::fromStdString(model_->view().error());
  text_error_->setText(error);
  text_error_->setVisible(!error.isEmpty());
  text_->setStyleSheet(error.isEmpty() ? QString() : "border: 1px solid #c00000");
  UpdateCounts();
  ScheduleSave();
}

// ---------------------------------------------------------------------------------------------
// selection: copy and export

std::vector<int> LogViewerWindow::SelectedRows() const {
  std::vector<int> rows;
  for (const QModelIndex& index : table_->selectionModel()->selectedRows())
    rows.push_back(index.row());
  std::sort(rows.begin(), rows.end());
  return rows;
}

void LogViewerWindow::CopySelection() {
  const std::vector<int> rows = SelectedRows();
  if (rows.empty()) return;
  QApplication::clipboard()->setText(model_->CopyText(rows));
  statusBar()->showMessage(
      QString("copied %1 row%2").arg(rows.size()).arg(rows.size() == 1 ? "" : "s"), 5000);
}

bool LogViewerWindow::ExportTo(const QString& path, QString* error) {
  auto fail = [&](const QString& message) {
    if (error != nullptr) *error = message;
    statusBar()->showMessage(message, 10000);
    return false;
  };
  // a selection written over the file it came from, or over the session log the logger appends
  // to, would lose every record not selected
  auto same_file = [&path](const std::string& other) {
    std::error_code ec;
    return !other.empty() && std::filesystem::equivalent(path.toStdString(), other, ec);
  };
  if (same_file(file_.toStdString()))
    return fail(
        QString("will not export to %1: it is the file shown (choose another file)").arg(path));
  const std::string live_log = link_status().session_file;
  if (same_file(live_log))
    return fail(QString("will not export to %1: it is the session log %2 is writing (choose "
                        "another file)")
                    .arg(path, QString::fromStdString(options_.link.instance)));
  std::vector<int> rows = SelectedRows();
  if (rows.empty()) {
    rows.resize(static_cast<size_t>(model_->rowCount()));
    for (size_t i = 0; i < rows.size(); ++i) rows[i] = static_cast<int>(i);
  }
  const QString from = file_.isEmpty() ? QString::fromStdString(options_.link.instance) : file_;
  const std::vector<logging::Record> records = model_->RecordsAt(rows);
  std::vector<const logging::Record*> pointers;
  pointers.reserve(records.size());
  for (const auto& r : records) pointers.push_back(&r);
  try {
    WriteSessionFile(path.toStdString(), pointers,
                     "exported by caliper-logviewer from " + from.toStdString() + "; " +
                         std::to_string(rows.size()) + " records");
  } catch (const std::exception& e) {
    return fail(QString::fromStdString(e.what()));
  }
  statusBar()->showMessage(QString("exported %1 records to %2").arg(rows.size()).arg(path), 5000);
  return true;
}

void LogViewerWindow::OpenFileDialog() {
  QString dir = file_.isEmpty()
                    ? QString::fromStdString(core::ExpandHome("~/.local/state/caliper/logs"))
                    : QFileInfo(file_).absolutePath();
  if (!QDir(dir).exists()) dir = QDir::homePath();
  const QString path = QFileDialog::getOpenFileName(this, "Open a session log", dir,
                                                    "Session logs (*.log);;All files (*)");
  if (path.isEmpty()) return;
  QString error;
  if (!OpenFile(path, &error)) QMessageBox::warning(this, "Open a session log", error);
}

void LogViewerWindow::ExportDialog() {
  const QString name = QString("caliper-export-%1.log")
                           .arg(QDateTime::currentDateTime().toString("yyyyMMdd-HHmmss"));
  const QString dir = file_.isEmpty() ? QDir::homePath() : QFileInfo(file_).absolutePath();
  const QString path =
      QFileDialog::getSaveFileName(this, "Export the selected records", QDir(dir).filePath(name),
                                   "Session logs (*.log);;All files (*)");
  if (path.isEmpty()) return;
  QString error;
  if (!ExportTo(path, &error)) QMessageBox::warning(this, "Export", error);
}

// ---------------------------------------------------------------------------------------------
// session

void LogViewerWindow::RestoreSession() {
  if (options_.session_file.isEmpty()) return;
  QSettings st(options_.session_file, QSettings::IniFormat);
  st.beginGroup(kGroup);
  // a value this version does not understand keeps the default and is reported, not dropped
  // silently
  QStringList ignored;
  auto ignore = [&ignored, &st](const char* key) {
    ignored << QString("%1=%2").arg(key, st.value(key).toString());
  };
  FilterSettings s;
  const QString priority = st.value("min_priority", "all").toString();
  int p = logging::kDebug;
  if (priority == "all") {
    s.max_priority = logging::kDebug;
  } else if (logging::ParsePriority(priority.toStdString(), &p)) {
    s.max_priority = p;
  } else {
    ignore("min_priority");
  }
  auto mode = [&](const char* key) {
    FilterMode m = FilterMode::kHide;
    if (st.contains(key) && !ParseMode(st.value(key).toString().toStdString(), &m)) ignore(key);
    return m;
  };
  auto flag = [&](const char* key, bool fallback) {
    if (!st.contains(key)) return fallback;
    const QString v = st.value(key).toString();
    if (v == "true") return true;
    if (v == "false") return false;
    ignore(key);
    return fallback;
  };
  auto time = [&](const char* key) -> int64_t {
    if (!st.contains(key)) return 0;
    bool ok = false;
    const qlonglong v = st.value(key).toString().toLongLong(&ok);
    if (ok) return v;
    ignore(key);
    return 0;
  };
  s.mode[kPriority] = mode("priority_mode");
  for (const QString& c : st.value("excluded_categories").toStringList())
    s.excluded_categories.insert(c.toStdString());
  s.mode[kCategory] = mode("category_mode");
  for (const QString& c : st.value("excluded_components").toStringList())
    s.excluded_components.insert(c.toStdString());
  s.mode[kComponent] = mode("component_mode");
  s.text = st.value("text").toString().toStdString();
  s.regex = flag("regex", false);
  s.case_sensitive = flag("case_sensitive", false);
  s.mode[kText] = mode("text_mode");
  s.from_time_us = time("from_time_us");
  s.to_time_us = time("to_time_us");
  s.mode[kTime] = mode("time_mode");
  follow_tail_->setChecked(flag("follow_tail", true));
  show_filters_->setChecked(flag("filters_visible", true));
  splitter_->restoreState(st.value("splitter").toByteArray());
  filter_splitter_->restoreState(st.value("filter_splitter").toByteArray());
  table_->horizontalHeader()->restoreState(st.value("columns").toByteArray());
  st.endGroup();
  ShowFilter(s);
  ApplyFilters();
  save_timer_->stop();  // nothing changed yet
  if (!ignored.isEmpty()) {
    session_problem_ =
        QString("%1 [%2]: ignored %3 (not understood; the defaults stay)")
            .arg(QFileInfo(options_.session_file).fileName(), kGroup, ignored.join(", "));
    ShowProblems();
  }
}

void LogViewerWindow::SaveSession() {
  save_timer_->stop();
  if (options_.session_file.isEmpty()) return;
  const FilterSettings s = CurrentFilter();
  QSettings st(options_.session_file, QSettings::IniFormat);
  st.beginGroup(kGroup);
  st.setValue("min_priority", s.max_priority >= logging::kDebug
                                  ? QString("all")
                                  : QString::fromStdString(logging::PriorityName(s.max_priority)));
  auto list = [](const std::set<std::string>& names) {
    QStringList out;
    for (const auto& n : names) out << QString::fromStdString(n);
    return out;
  };
  st.setValue("priority_mode", ModeName(s.mode[kPriority]));
  st.setValue("excluded_categories", list(s.excluded_categories));
  st.setValue("category_mode", ModeName(s.mode[kCategory]));
  st.setValue("excluded_components", list(s.excluded_components));
  st.setValue("component_mode", ModeName(s.mode[kComponent]));
  st.setValue("text", QString::fromStdString(s.text));
  st.setValue("regex", s.regex);
  st.setValue("case_sensitive", s.case_sensitive);
  st.setValue("text_mode", ModeName(s.mode[kText]));
  st.setValue("from_time_us", static_cast<qlonglong>(s.from_time_us));
  st.setValue("to_time_us", static_cast<qlonglong>(s.to_time_us));
  st.setValue("time_mode", ModeName(s.mode[kTime]));
  st.setValue("follow_tail", follow_tail_->isChecked());
  st.setValue("filters_visible", show_filters_->isChecked());
  st.setValue("splitter", splitter_->saveState());
  st.setValue("filter_splitter", filter_splitter_->saveState());
  st.setValue("columns", table_->horizontalHeader()->saveState());
  st.endGroup();
  st.sync();
  tool_window_->Save();
}

void LogViewerWindow::ScheduleSave() {
  if (!options_.session_file.isEmpty()) save_timer_->start(options_.save_delay_ms);
}

void LogViewerWindow::closeEvent(QCloseEvent* event) {
  SaveSession();
  poll_timer_->stop();
  link_.reset();  // unregister now rather than when the window is destroyed
  QMainWindow::closeEvent(event);
}

bool LogViewerWindow::eventFilter(QObject* watched, QEvent* event) {
  // the table's own Ctrl+C copies one cell: whole rows instead
  if (watched == table_ && event->type() == QEvent::KeyPress &&
      static_cast<QKeyEvent*>(event)->matches(QKeySequence::Copy)) {
    CopySelection();
    return true;
  }
  return QMainWindow::eventFilter(watched, event);
}

}  // namespace caliper::log_viewer
