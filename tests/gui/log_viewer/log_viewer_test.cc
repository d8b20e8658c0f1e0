// The Log Viewer in the test process (widgets on QT_QPA_PLATFORM=offscreen): the known session
// file filtered through the widgets, copy and export of a selection (never over the file shown
// or the live session log), the session settings shared with the Main Window (values not
// understood reported), the listener servant keeping every exception in, following a real
// caliper-logger live across a restart, closing while that logger is stopped mid-query, and the
// caliper-logviewer program itself (usage, errors, SIGTERM unregistering its listener).
#include <gtest/gtest.h>
#include <signal.h>

#include <QAction>
#include <QApplication>
#include <QRegularExpression>
#include <QBrush>
#include <QCheckBox>
#include <QClipboard>
#include <QComboBox>
#include <QDateTime>
#include <QDateTimeEdit>
#include <QElapsedTimer>
#include <QItemSelectionModel>
#include <QLabel>
#include <QLineEdit>
#include <QSettings>
#include <QSplitter>
#include <QStyle>
#include <QStyleOptionViewItem>
#include <QTableView>
#include <QTest>
#include <QTreeWidget>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "caliper/gui_session/tool_window.h"
#include "caliper/logging.hh"
#include "caliper/rtc.hh"
#include "caliper/rtc/log_service_sink.h"
#include "caliper/rtc/naming.h"
#include "known_session.h"
#include "listener_servant.h"
#include "log_viewer_window.h"
#include "session_file.h"
#include "support/gui_test.h"
#include "support/process.h"

namespace caliper::log_viewer {
namespace {

namespace k = testing;
using caliper::testing::Bin;
using caliper::testing::Ctl;
using caliper::testing::NamingService;
using caliper::testing::Process;
using caliper::testing::ReadFile;
using caliper::testing::RunCommand;
using caliper::testing::TempDir;
using caliper::testing::WaitFor;
using std::chrono::milliseconds;
using std::chrono::seconds;

// Processes events until `condition` holds or `timeout` (5 s unless given) passes.
bool WaitInGui(const std::function<bool()>& condition, milliseconds timeout = seconds(5)) {
  return caliper::testing::WaitInGui(condition, timeout);
}

template <typename W>
W* Child(QWidget& window, const char* name) {
  W* w = window.findChild<W*>(name);
  if (w == nullptr) ADD_FAILURE() << "no widget named " << name;
  return w;
}

// A node of the sources tree by its text under a top-level node ("Categories", "Components").
QTreeWidgetItem* SourceItem(QTreeWidget* tree, const QString& top, const QString& text) {
  for (int i = 0; i < tree->topLevelItemCount(); ++i) {
    QTreeWidgetItem* root = tree->topLevelItem(i);
    if (root->text(0) != top) continue;
    for (int j = 0; j < root->childCount(); ++j)
      if (root->child(j)->text(0) == text) return root->child(j);
  }
  return nullptr;
}

// Clicks the check box of a tree item as a user would.
void ClickCheckBox(QTreeWidget* tree, QTreeWidgetItem* item) {
  tree->scrollToItem(item);
  QStyleOptionViewItem option;
  option.initFrom(tree->viewport());
  option.rect = tree->visualItemRect(item);
  option.features |= QStyleOptionViewItem::HasCheckIndicator;
  const QRect box =
      tree->style()->subElementRect(QStyle::SE_ItemViewItemCheckIndicator, &option, tree);
  QTest::mouseClick(tree->viewport(), Qt::LeftButton, Qt::NoModifier, box.center());
}

// Replaces the text of a line edit by typing.
void Type(QLineEdit* edit, const QString& text) {
  edit->setFocus();
  edit->selectAll();
  QTest::keyClick(edit, Qt::Key_Backspace);
  QTest::keyClicks(edit, text);
}

// Shown rows, waited for: the filters apply after a short pause.
bool ShowsRows(LogViewerWindow& w, int rows) {
  const bool reached = WaitInGui([&] { return w.model().rowCount() == rows; });
  QTest::qWait(350);  // and it stays there once the typing pause is over
  return reached && w.model().rowCount() == rows;
}

int RowsOfComponent(LogViewerWindow& w, const std::string& component) {
  int n = 0;
  for (int row = 0; row < w.model().rowCount(); ++row)
    n += w.model().RecordAt(row).component == component ? 1 : 0;
  return n;
}

class LogViewerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // run directly rather than through ctest: the programs are in the build tree
    setenv("CALIPER_BIN_DIR", CALIPER_BIN_DIR_DEFAULT, 0);
    caliper::testing::App();
    caliper::testing::Orb();
  }

  std::unique_ptr<LogViewerWindow> Window(LogViewerWindow::Options options = {}) {
    options.link.retry_period_ms = 300;
    options.link.check_period_ms = 300;
    options.poll_ms = 50;
    auto w = std::make_unique<LogViewerWindow>(options);
    w->show();
    return w;
  }

  TempDir dir_;
};

TEST_F(LogViewerTest, KnownFileFilteredThroughTheWidgets) {
  auto w = Window();
  ASSERT_TRUE(w->OpenFile(QString::fromStdString(k::KnownSessionPath())));
  EXPECT_EQ(w->model().rowCount(), k::kKnownRecords);
  EXPECT_FALSE(w->live());
  // the time of day in the table, the full date and time in its tooltip
  const QModelIndex first_time = w->model().index(0, 0);
  const QString shown = w->model().data(first_time, Qt::DisplayRole).toString();
  const QString full = w->model().data(first_time, Qt::ToolTipRole).toString();
  EXPECT_TRUE(QRegularExpression(R"(^\d\d:\d\d:\d\d\.\d{3}$)").match(shown).hasMatch())
      << shown.toStdString();
  EXPECT_TRUE(QRegularExpression(R"(^\d{4}-\d\d-\d\d )").match(full).hasMatch()) << full.toStdString();
  EXPECT_TRUE(full.endsWith(shown)) << full.toStdString();
  ASSERT_EQ(w->problems().size(), 1);
  EXPECT_TRUE(w->problems()[0].contains("known_session.log:19: not a log record"))
      << w->problems()[0].toStdString();
  EXPECT_TRUE(Child<QLabel>(*w, "problems")->text().startsWith("1 malformed line skipped: "));
  EXPECT_TRUE(Child<QLabel>(*w, "connection")->text().startsWith("File: "));
  auto* tree = Child<QTreeWidget>(*w, "sources");
  for (const char* c : {"model0", "pd0", "renderer0", "logger0"})
    EXPECT_NE(SourceItem(tree, "Components", c), nullptr) << c;
  ASSERT_NE(SourceItem(tree, "Categories", "caliper"), nullptr);
  EXPECT_EQ(SourceItem(tree, "Categories", "caliper")->childCount(),
            4);  // logger model pd renderer

  // priority: typing in the combo picks WARN
  auto* priority = Child<QComboBox>(*w, "priority");
  priority->setFocus();
  QTest::keyClicks(priority, "W");
  EXPECT_EQ(priority->currentText(), "WARN");
  EXPECT_TRUE(ShowsRows(*w, k::kWarnOrWorse));

  // component: uncheck model0 in the tree
  QTreeWidgetItem* model0 = SourceItem(tree, "Components", "model0");
  ClickCheckBox(tree, model0);
  EXPECT_EQ(model0->checkState(0), Qt::Unchecked);
  EXPECT_TRUE(ShowsRows(*w, 4));  // 14 renderer0 WARN, 16 pd0 ERROR, 24 pd0 WARN, 26 logger0 FATAL

  // a regular expression
  auto* regex = Child<QCheckBox>(*w, "regex");
  QTest::mouseClick(regex, Qt::LeftButton, Qt::NoModifier, QPoint(8, regex->height() / 2));
  EXPECT_TRUE(regex->isChecked());
  auto* text = Child<QLineEdit>(*w, "text");
  Type(text, "lost|disk");
  EXPECT_TRUE(ShowsRows(*w, 2));
  auto* error = Child<QLabel>(*w, "text_error");
  EXPECT_TRUE(error->isHidden());

  // a bad one: an error under the field, the text filter off, no crash
  Type(text, "(lost");
  EXPECT_TRUE(ShowsRows(*w, 4));
  EXPECT_FALSE(error->isHidden());
  EXPECT_EQ(error->text().toStdString(), "bad regular expression '(lost': missing ): (lost");

  // clear filters (the modes stay), then highlight "tendon" instead of hiding
  w->findChild<QAction*>("clear_filters")->trigger();
  EXPECT_TRUE(ShowsRows(*w, k::kKnownRecords));
  EXPECT_EQ(model0->checkState(0), Qt::Checked);
  EXPECT_TRUE(error->isHidden());
  auto* text_mode = Child<QComboBox>(*w, "text_mode");
  text_mode->setFocus();
  QTest::keyClicks(text_mode, "Hig");
  EXPECT_EQ(text_mode->currentText(), "Highlight");
  Type(text, "tendon");
  EXPECT_TRUE(WaitInGui([&] { return w->model().view().highlighted_count() == 4; }));
  EXPECT_TRUE(ShowsRows(*w, k::kKnownRecords));
  const LogModel& m = w->model();
  auto brush = [&](int row, int role) {
    return m.data(m.index(row, LogModel::kMessageColumn), role).value<QBrush>();
  };
  EXPECT_EQ(brush(2, Qt::BackgroundRole).style(), Qt::SolidPattern);  // "... 6 tendons"
  EXPECT_EQ(brush(1, Qt::BackgroundRole).style(), Qt::NoBrush);
  EXPECT_EQ(brush(10, Qt::ForegroundRole).color(), QColor(200, 0, 0));   // ERROR: red
  EXPECT_EQ(brush(6, Qt::ForegroundRole).color(), QColor(215, 110, 0));  // WARN: orange
  EXPECT_EQ(brush(1, Qt::ForegroundRole).style(), Qt::NoBrush);          // NOTICE: plain
  EXPECT_TRUE(
      Child<QLabel>(*w, "counts")->text().contains("30 of 30 records shown, 4 highlighted"));

  // the screenshot: every row, errors red, warnings orange, "tendon" highlighted
  w->resize(1280, 720);
  tree->scrollToTop();
  QApplication::processEvents();
  const std::string png = caliper::testing::ArtifactPath("log_viewer.png", dir_.path());
  EXPECT_TRUE(w->grab().save(QString::fromStdString(png)));

  // time range, typed into the date-time edits: records 11 to 20, record 11 highlighted
  auto* from = Child<QDateTimeEdit>(*w, "from");
  auto* to = Child<QDateTimeEdit>(*w, "to");
  QTest::mouseClick(Child<QCheckBox>(*w, "from_enabled"), Qt::LeftButton, Qt::NoModifier,
                    QPoint(8, 8));
  QTest::mouseClick(Child<QCheckBox>(*w, "to_enabled"), Qt::LeftButton, Qt::NoModifier,
                    QPoint(8, 8));
  from->setDateTime(QDateTime::fromMSecsSinceEpoch(k::kKnownStartUs / 1000 + 10000));
  to->setDateTime(QDateTime::fromMSecsSinceEpoch(k::kKnownStartUs / 1000 + 19999));
  EXPECT_TRUE(ShowsRows(*w, 10));
  EXPECT_EQ(w->model().view().highlighted_count(), 1u);
}

TEST_F(LogViewerTest, CopiesAndExportsTheSelection) {
  auto w = Window();
  ASSERT_TRUE(w->OpenFile(QString::fromStdString(k::KnownSessionPath())));
  w->activateWindow();
  QTableView* table = w->table();
  table->setFocus();
  QApplication::clipboard()->clear();
  // rows 1, 2 and 27 (the message with a tab and a newline) selected with the mouse
  auto click = [&](int row, Qt::KeyboardModifiers modifiers) {
    table->scrollTo(w->model().index(row, 0));
    const QRect r = table->visualRect(w->model().index(row, LogModel::kPriorityColumn));
    QTest::mouseClick(table->viewport(), Qt::LeftButton, modifiers, r.center());
  };
  click(1, Qt::NoModifier);
  click(2, Qt::ShiftModifier);
  click(26, Qt::ControlModifier);
  ASSERT_EQ(table->selectionModel()->selectedRows().size(), 3);
  QTest::keyClick(table, Qt::Key_C, Qt::ControlModifier);
  const QStringList lines = QApplication::clipboard()->text().split('\n', Qt::SkipEmptyParts);
  ASSERT_EQ(lines.size(), 3) << QApplication::clipboard()->text().toStdString();
  const QStringList fields = lines[0].split('\t');
  ASSERT_EQ(fields.size(), 6);
  EXPECT_EQ(fields[1], "NOTICE");
  EXPECT_EQ(fields[2], "caliper.model.rtc");
  EXPECT_EQ(fields[3], "model0");
  EXPECT_EQ(fields[4], "node1");
  EXPECT_EQ(fields[5], "model0 bound in the naming service");
  EXPECT_EQ(lines[2].split('\t').size(), 6) << "tabs in a message must not add columns";

  // export the same selection; it reads back identically and opens again
  const QString path = QString::fromStdString(dir_.path() + "/export.log");
  QString error;
  ASSERT_TRUE(w->ExportTo(path, &error)) << error.toStdString();
  const auto original = ReadSessionFile(k::KnownSessionPath()).records;
  const auto exported = ReadSessionFile(path.toStdString());
  EXPECT_EQ(exported.malformed, 0u);
  ASSERT_EQ(exported.records.size(), 3u);
  const size_t picked[] = {1, 2, 26};
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(logging::FormatLine(exported.records[i]), logging::FormatLine(original[picked[i]]));
  }
  ASSERT_TRUE(w->OpenFile(path));
  EXPECT_EQ(w->model().rowCount(), 3);
  EXPECT_TRUE(w->problems().isEmpty());

  // nothing selected: every shown row is exported; a bad path is an error naming the reason,
  // not a crash
  const QString again = QString::fromStdString(dir_.path() + "/again.log");
  ASSERT_TRUE(w->ExportTo(again, &error)) << error.toStdString();
  EXPECT_EQ(ReadSessionFile(again.toStdString()).records.size(), 3u);
  EXPECT_FALSE(w->ExportTo("/nonexistent/dir/x.log", &error));
  EXPECT_TRUE(error.startsWith("cannot write /nonexistent/dir/x.log")) << error.toStdString();
  EXPECT_TRUE(error.contains("No such file or directory")) << error.toStdString();
  EXPECT_FALSE(w->OpenFile("/nonexistent/dir/x.log", &error));
  EXPECT_EQ(w->model().rowCount(), 3) << "a failed open leaves the table as it was";
}

TEST_F(LogViewerTest, SessionFileKeepsGeometryAndFilters) {
  const QString ini = QString::fromStdString(dir_.path() + "/caliper-main.ini");
  {
    // the Main Window's own keys must survive
    QSettings st(ini, QSettings::IniFormat);
    st.setValue("window/geometry", QRect(1, 2, 300, 200));
  }
  LogViewerWindow::Options options;
  options.session_file = ini;
  options.save_delay_ms = 100;
  {
    auto w = Window(options);
    w->setGeometry(QRect(50, 60, 900, 500));
    auto* priority = Child<QComboBox>(*w, "priority");
    priority->setCurrentIndex(priority->findText("ERROR"));
    Child<QCheckBox>(*w, "regex")->setChecked(true);
    Type(Child<QLineEdit>(*w, "text"), "tendon|lost");
    auto* mode = Child<QComboBox>(*w, "text_mode");
    mode->setCurrentIndex(mode->findText("Highlight"));
    ASSERT_TRUE(w->OpenFile(QString::fromStdString(k::KnownSessionPath())));
    ClickCheckBox(Child<QTreeWidget>(*w, "sources"),
                  SourceItem(Child<QTreeWidget>(*w, "sources"), "Components", "renderer0"));
    w->ApplyFilters();
    // the filter panel hidden: the table takes the window, the filters stay in force
    auto* panel = Child<QSplitter>(*w, "splitter")->widget(0);
    ASSERT_TRUE(panel->isVisible());
    Child<QAction>(*w, "show_filters")->trigger();
    EXPECT_FALSE(panel->isVisible());
    // a resize is saved after a pause, without closing
    w->resize(880, 480);
    EXPECT_TRUE(WaitInGui(
        [&] { return gui_session::ReadToolWindow(ini, "log_viewer").geometry.width() == 880; }));
    w->close();
  }
  QSettings st(ini, QSettings::IniFormat);
  EXPECT_EQ(st.value("window/geometry").toRect(), QRect(1, 2, 300, 200));
  EXPECT_EQ(st.value("log_viewer/min_priority").toString(), "ERROR");
  EXPECT_EQ(st.value("log_viewer/text").toString(), "tendon|lost");
  EXPECT_EQ(st.value("log_viewer/text_mode").toString(), "highlight");
  EXPECT_EQ(st.value("log_viewer/excluded_components").toStringList(), QStringList{"renderer0"});
  EXPECT_FALSE(st.value("log_viewer/filters_visible").toBool());

  // a new viewer comes back as it was left
  auto again = Window(options);
  EXPECT_EQ(again->geometry().size(), QSize(880, 480));
  EXPECT_EQ(Child<QComboBox>(*again, "priority")->currentText(), "ERROR");
  EXPECT_EQ(Child<QLineEdit>(*again, "text")->text(), "tendon|lost");
  EXPECT_TRUE(Child<QCheckBox>(*again, "regex")->isChecked());
  EXPECT_EQ(Child<QComboBox>(*again, "text_mode")->currentText(), "Highlight");
  ASSERT_TRUE(again->OpenFile(QString::fromStdString(k::KnownSessionPath())));
  EXPECT_EQ(
      SourceItem(Child<QTreeWidget>(*again, "sources"), "Components", "renderer0")->checkState(0),
      Qt::Unchecked);
  EXPECT_FALSE(Child<QAction>(*again, "show_filters")->isChecked());
  EXPECT_FALSE(Child<QSplitter>(*again, "splitter")->widget(0)->isVisible());
  // ERROR or worse without renderer0: records 11, 16, 19, 26, 29; 11 and 16 highlighted
  EXPECT_EQ(again->model().rowCount(), 5);
  EXPECT_EQ(again->model().view().highlighted_count(), 2u);
  again->close();

  // the record the Main Window reads to place and arrange its tools
  const gui_session::ToolWindowRecord record = gui_session::ReadToolWindow(ini, "log_viewer");
  EXPECT_EQ(record.geometry.size(), QSize(880, 480));
  EXPECT_EQ(record.pid, QCoreApplication::applicationPid());

  // small enough for the Main Window's arrangement (a third of an 800 px screen's height)
  EXPECT_LE(again->minimumSizeHint().height(), 260)
      << again->minimumSizeHint().width() << "x" << again->minimumSizeHint().height();
  EXPECT_LE(again->minimumSizeHint().width(), 520)
      << again->minimumSizeHint().width() << "x" << again->minimumSizeHint().height();

  // --geometry wins over the session's
  ASSERT_TRUE(gui_session::ParseGeometry("640x400+30+40", &options.geometry));
  auto placed = Window(options);
  EXPECT_EQ(placed->geometry().size(), QSize(640, 400));
}

TEST_F(LogViewerTest, ExportRefusesToWriteOverTheFileShown) {
  // a copy of the known file, shown; exporting a selection over it would lose the rest
  const std::string shown = dir_.path() + "/shown.log";
  std::filesystem::copy_file(k::KnownSessionPath(), shown);
  const std::string before = ReadFile(shown);
  auto w = Window();
  ASSERT_TRUE(w->OpenFile(QString::fromStdString(shown)));
  w->table()->selectRow(0);
  QString error;
  EXPECT_FALSE(w->ExportTo(QString::fromStdString(shown), &error));
  EXPECT_EQ(error.toStdString(),
            "will not export to " + shown + ": it is the file shown (choose another file)");
  // also under another name
  const std::string link = dir_.path() + "/link.log";
  std::filesystem::create_symlink(shown, link);
  EXPECT_FALSE(w->ExportTo(QString::fromStdString(link), &error));
  EXPECT_TRUE(error.contains("it is the file shown")) << error.toStdString();
  EXPECT_EQ(ReadFile(shown), before) << "the file shown is untouched";
  // anywhere else is fine
  EXPECT_TRUE(w->ExportTo(QString::fromStdString(dir_.path() + "/other.log"), &error))
      << error.toStdString();
}

TEST_F(LogViewerTest, SessionValuesNotUnderstoodAreReportedAndKeepTheDefaults) {
  const QString ini = QString::fromStdString(dir_.path() + "/caliper-main.ini");
  {
    QSettings st(ini, QSettings::IniFormat);
    st.beginGroup("log_viewer");
    st.setValue("min_priority", "LOUD");
    st.setValue("priority_mode", "highlight");  // understood
    st.setValue("text", "tendon");              // understood
    st.setValue("text_mode", "blink");
    st.setValue("regex", "perhaps");
    st.setValue("from_time_us", "yesterday");
    st.setValue("to_time_us", "1709632810000000");  // understood
    st.endGroup();
  }
  LogViewerWindow::Options options;
  options.session_file = ini;
  auto w = Window(options);
  const std::string problem = w->session_problem().toStdString();
  for (const char* ignored :
       {"min_priority=LOUD", "text_mode=blink", "regex=perhaps", "from_time_us=yesterday"})
    EXPECT_NE(problem.find(ignored), std::string::npos) << ignored << " in: " << problem;
  for (const char* understood : {"priority_mode", "text=", "to_time_us"})
    EXPECT_EQ(problem.find(understood), std::string::npos) << understood << " in: " << problem;
  EXPECT_EQ(problem.rfind("caliper-main.ini [log_viewer]: ignored ", 0), 0u) << problem;
  EXPECT_TRUE(Child<QLabel>(*w, "problems")->text().contains("min_priority=LOUD"))
      << "on the status line";
  // the defaults stay where a value was not understood, the rest is restored
  EXPECT_EQ(Child<QComboBox>(*w, "priority")->currentText(), "DEBUG (all)");
  EXPECT_EQ(Child<QComboBox>(*w, "priority_mode")->currentText(), "Highlight");
  EXPECT_EQ(Child<QComboBox>(*w, "text_mode")->currentText(), "Hide others");
  EXPECT_FALSE(Child<QCheckBox>(*w, "regex")->isChecked());
  EXPECT_EQ(Child<QLineEdit>(*w, "text")->text(), "tendon");
  EXPECT_FALSE(Child<QCheckBox>(*w, "from_enabled")->isChecked());
  EXPECT_TRUE(Child<QCheckBox>(*w, "to_enabled")->isChecked());
  // opening a file keeps the report next to the file's own problems
  ASSERT_TRUE(w->OpenFile(QString::fromStdString(k::KnownSessionPath())));
  const QString shown = Child<QLabel>(*w, "problems")->text();
  EXPECT_TRUE(shown.startsWith("1 malformed line skipped: ")) << shown.toStdString();
  EXPECT_TRUE(shown.contains("min_priority=LOUD")) << shown.toStdString();

  // a session the viewer wrote itself has nothing to report
  w->close();
  auto again = Window(options);
  EXPECT_TRUE(again->session_problem().isEmpty()) << again->session_problem().toStdString();
  EXPECT_EQ(Child<QLineEdit>(*again, "text")->text(), "tendon");
}

TEST_F(LogViewerTest, ListenerServantKeepsEveryExceptionIn) {
  // a pushed batch that cannot be taken in must not reach the logger as UNKNOWN (it would drop
  // the listener): it is counted instead
  Caliper::Logging::StoredRecordSeq batch;
  batch.length(1);
  batch[0].serial = 1;
  batch[0].rec.message = "pushed";
  int thrown = 0;
  auto* servant = new ListenerServant([&thrown](std::vector<LiveRecord> records) {
    EXPECT_EQ(records.size(), 1u);
    if (++thrown == 1) throw std::runtime_error("inbox full");
    throw 42;
  });
  EXPECT_NO_THROW(servant->on_records(batch));
  EXPECT_EQ(servant->failures(), 1u);
  EXPECT_EQ(servant->last_failure(), "inbox full");
  EXPECT_NO_THROW(servant->on_records(batch));
  EXPECT_EQ(servant->failures(), 2u);
  EXPECT_EQ(servant->last_failure(), "an unknown exception");
  servant->_remove_ref();
}

class LiveTest : public LogViewerTest {
 protected:
  void SetUp() override {
    LogViewerTest::SetUp();
    naming_ = std::make_unique<NamingService>(dir_.path());
  }

  std::unique_ptr<Process> StartLogger() {
    return std::make_unique<Process>(
        std::vector<std::string>{Bin("caliper-logger"), "--nameservice", naming_->address(), "-o",
                                 "logger.directory=" + dir_.path() + "/logs", "-o",
                                 "logger.session=test", "-o",
                                 "log.spool_dir=" + dir_.path() + "/spool"},
        dir_.path() + "/logger.out");
  }

  // Records `first`..`last` of the test's source, sent until the logger takes them.
  bool Send(uint64_t first, uint64_t last, int priority = logging::kInfo) {
    std::vector<logging::Record> batch;
    for (uint64_t seq = first; seq <= last; ++seq) {
      logging::Record r;
      r.time_us = 1709632800LL * 1000000 + static_cast<int64_t>(seq) * 1000;
      r.priority = priority;
      r.category = "caliper.test.live";
      r.component = "live0";
      r.host = "testhost";
      r.pid = 42;
      r.source = "testhost:42:1";
      r.seq = seq;
      r.message = "live record " + std::to_string(seq);
      batch.push_back(r);
    }
    rtc::LogServiceSink sink(caliper::testing::Orb(), naming_->address(), "logger0");
    return WaitFor(
        [&] {
          try {
            sink.Send(batch);
            return true;
          } catch (const logging::SinkUnavailable&) {
            return false;
          }
        },
        seconds(15));
  }

  // a session log of `n` records that the logger reads back when it starts (same session)
  void WriteBacklog(int n) {
    std::filesystem::create_directories(dir_.path() + "/logs");
    std::vector<logging::Record> records(static_cast<size_t>(n));
    std::vector<const logging::Record*> all;
    for (int i = 0; i < n; ++i) {
      logging::Record& r = records[static_cast<size_t>(i)];
      r.time_us = 1709632800LL * 1000000 + i;
      r.category = "caliper.test.backlog";
      r.component = "backlog0";
      r.host = "testhost";
      r.pid = 43;
      r.source = "testhost:43:1";
      r.seq = static_cast<uint64_t>(i) + 1;
      r.message = "backlog record " + std::to_string(i + 1) + " with some text to carry";
      all.push_back(&r);
    }
    WriteSessionFile(dir_.path() + "/logs/caliper-20240305-100000-test.log", all);
  }

  std::string SessionLog() {
    const auto files = caliper::testing::ListFiles(dir_.path() + "/logs", "caliper-");
    return files.size() == 1 ? ReadFile(files[0]) : "";
  }

  std::unique_ptr<NamingService> naming_;
};

TEST_F(LiveTest, FollowsTheLoggerAndRegistersAgainAfterItRestarts) {
  auto logger = StartLogger();
  ASSERT_TRUE(Send(1, 5)) << logger->Output();  // before the viewer: its first query has them

  LogViewerWindow::Options options;
  options.link.nameservice = naming_->address();
  auto w = Window(options);
  w->FollowLive();
  ASSERT_TRUE(WaitInGui([&] { return w->link_status().connected; }, seconds(10)))
      << w->link_status().message;
  EXPECT_TRUE(WaitInGui([&] { return RowsOfComponent(*w, "live0") == 5; }));
  auto* connection = Child<QLabel>(*w, "connection");
  EXPECT_TRUE(connection->text().startsWith("Live: connected")) << connection->text().toStdString();
  EXPECT_TRUE(connection->text().contains("caliper-")) << "names the session log";
  // exporting the selection over the session log the logger appends to is refused
  const std::string live_log = w->link_status().session_file;
  const std::string before = ReadFile(live_log);
  w->table()->selectRow(0);
  QString error;
  EXPECT_FALSE(w->ExportTo(QString::fromStdString(live_log), &error));
  EXPECT_EQ(error.toStdString(), "will not export to " + live_log +
                                     ": it is the session log logger0 is writing (choose "
                                     "another file)");
  EXPECT_EQ(ReadFile(live_log), before);

  ASSERT_TRUE(Send(6, 15, logging::kError));  // pushed to the listener
  EXPECT_TRUE(WaitInGui([&] { return RowsOfComponent(*w, "live0") == 15; }));
  EXPECT_NE(SourceItem(Child<QTreeWidget>(*w, "sources"), "Components", "live0"), nullptr);
  // the live rows go through the filters too
  auto* priority = Child<QComboBox>(*w, "priority");
  priority->setCurrentIndex(priority->findText("ERROR"));
  EXPECT_TRUE(WaitInGui([&] { return RowsOfComponent(*w, "live0") == 10; }));
  priority->setCurrentIndex(0);
  EXPECT_TRUE(WaitInGui([&] { return RowsOfComponent(*w, "live0") == 15; }));

  // the logger forgets the listener (as it does after one failed push): the viewer notices that
  // records wait while none arrive, and registers again
  {
    CosNaming::NamingContext_var root =
        rtc::ResolveRoot(caliper::testing::Orb(), naming_->address());
    Caliper::Logging::LogService_var service =
        Caliper::Logging::LogService::_narrow(rtc::FindComponent(root, "logger0").object);
    for (CORBA::ULongLong id = 1; id <= 3; ++id) service->remove_listener(id);
  }
  ASSERT_TRUE(Send(16, 20));
  EXPECT_TRUE(WaitInGui([&] { return RowsOfComponent(*w, "live0") == 20; }, seconds(10)))
      << RowsOfComponent(*w, "live0");
  EXPECT_EQ(w->link_status().registrations, 2u);

  // the logger dies: the status line says so, and the GUI stays responsive
  logger->Signal(SIGKILL);
  logger->Wait(seconds(5));
  EXPECT_TRUE(WaitInGui([&] { return !w->link_status().connected; }, seconds(10)));
  EXPECT_TRUE(
      WaitInGui([&] { return connection->text().startsWith("Live: not connected"); }, seconds(2)))
      << connection->text().toStdString();
  QElapsedTimer responsive;
  responsive.start();
  QApplication::processEvents();
  EXPECT_LT(responsive.elapsed(), 200);

  // it comes back (same session file): the viewer registers again and misses nothing
  logger = StartLogger();
  ASSERT_TRUE(WaitInGui([&] { return w->link_status().registrations >= 3; }, seconds(15)))
      << w->link_status().message;
  ASSERT_TRUE(Send(21, 30));
  EXPECT_TRUE(WaitInGui([&] { return RowsOfComponent(*w, "live0") == 30; }, seconds(10)))
      << RowsOfComponent(*w, "live0");
  QTest::qWait(500);
  EXPECT_EQ(RowsOfComponent(*w, "live0"), 30) << "no record twice";
  EXPECT_TRUE(w->link_status().connected);
  int last = 0;
  for (int row = 0; row < w->model().rowCount(); ++row) {
    const auto& r = w->model().RecordAt(row);
    if (r.component != "live0") continue;
    EXPECT_EQ(r.seq, static_cast<uint64_t>(++last)) << "in order";
  }

  // the session's own file, then the live service on top: what both have is shown once
  const QString session_log = QString::fromStdString(w->link_status().session_file);
  w.reset();
  auto both = Window(options);
  ASSERT_TRUE(both->OpenFile(session_log));
  EXPECT_EQ(RowsOfComponent(*both, "live0"), 30);
  const size_t from_file = both->model().store().size();
  both->FollowLive(/*keep=*/true);
  ASSERT_TRUE(WaitInGui([&] { return both->link_status().connected; }, seconds(10)));
  ASSERT_TRUE(Send(31, 31));
  EXPECT_TRUE(WaitInGui([&] { return RowsOfComponent(*both, "live0") == 31; }));
  QTest::qWait(300);
  EXPECT_EQ(RowsOfComponent(*both, "live0"), 31);
  EXPECT_GE(both->model().store().size(), from_file + 1);
}

TEST_F(LiveTest, ABacklogLargerThanOneReplyArrivesCompleteAndInOrder) {
  // some 6 MB of records: one reply would exceed omniORB's 2 MB message limit
  constexpr int kBacklog = 60000;
  WriteBacklog(kBacklog);
  auto logger = StartLogger();
  LogViewerWindow::Options options;
  options.link.nameservice = naming_->address();
  auto w = Window(options);
  w->FollowLive();
  ASSERT_TRUE(WaitInGui([&] { return w->link_status().connected; }, seconds(20)))
      << w->link_status().message;
  EXPECT_TRUE(WaitInGui([&] { return RowsOfComponent(*w, "backlog0") == kBacklog; }, seconds(10)))
      << RowsOfComponent(*w, "backlog0");
  uint64_t last = 0;
  for (int row = 0; row < w->model().rowCount(); ++row) {
    const logging::Record r = w->model().RecordAt(row);
    if (r.component != "backlog0") continue;
    ASSERT_EQ(r.seq, ++last) << "in order, none twice";
  }
  EXPECT_EQ(w->link_status().lost, 0u);
  EXPECT_EQ(w->link_status().registrations, 1u);
}

TEST_F(LiveTest, ClosingWhileTheLoggerIsStoppedMidQueryReturnsWithinSeconds) {
  WriteBacklog(200000);  // a first query that takes a while to answer
  auto logger = StartLogger();
  LogViewerWindow::Options options;
  options.link.nameservice = naming_->address();
  options.link.query_timeout_ms = 60000;  // the stalled query does not end by itself meanwhile
  auto w = Window(options);
  w->FollowLive();
  // the logger stops (kill -STOP) while the viewer waits for its backlog
  ASSERT_TRUE(WaitFor([&] { return w->link_status().message.rfind("reading the records", 0) == 0; },
                      seconds(30)))
      << w->link_status().message << "\n"
      << logger->Output();
  logger->Signal(SIGSTOP);
  QTest::qWait(500);
  ASSERT_FALSE(w->link_status().connected) << "the backlog arrived before the logger stopped";

  QElapsedTimer closing;
  closing.start();
  w->close();
  w.reset();
  EXPECT_LT(closing.elapsed(), 5000) << "closing waited for the stalled query";
  logger->Signal(SIGCONT);
  logger->Signal(SIGKILL);
  logger->Wait(seconds(5));
}

TEST_F(LogViewerTest, ModelKeepsAtMostMaxRecordsDroppingTheOldest) {
  LogModel model;
  model.set_max_records(100);
  auto batch = [](uint64_t first, uint64_t n) {
    std::vector<logging::Record> out;
    for (uint64_t seq = first; seq < first + n; ++seq) {
      logging::Record r;
      r.source = "s";
      r.seq = seq;
      out.push_back(r);
    }
    return out;
  };
  EXPECT_EQ(model.Append(batch(1, 90)), 90u);
  EXPECT_EQ(model.rowCount(), 90);
  model.Append(batch(91, 30));  // 120 > 100: the oldest go, 75 stay
  EXPECT_EQ(model.rowCount(), 75);
  EXPECT_EQ(model.RecordAt(0).seq, 46u);
  EXPECT_EQ(model.RecordAt(74).seq, 120u);
  EXPECT_EQ(model.Append(batch(100, 10)), 0u) << "seen before";
}

TEST_F(LiveTest, ProgramHelpErrorsAndCleanShutdown) {
  const auto help = RunCommand({Bin("caliper-logviewer"), "--help"});
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_EQ(help.out.rfind("usage: caliper-logviewer [--nameservice corbaname::HOST:PORT]", 0), 0u)
      << help.out;
  EXPECT_NE(help.out.find("--session FILE"), std::string::npos);
  const auto bad = RunCommand({Bin("caliper-logviewer"), "--bogus"});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("unknown option '--bogus'"), std::string::npos) << bad.err;
  const auto geometry = RunCommand({Bin("caliper-logviewer"), "--geometry", "10x"});
  EXPECT_EQ(geometry.exit_code, 2);
  EXPECT_NE(geometry.err.find("--geometry needs WIDTHxHEIGHT+X+Y"), std::string::npos);
  const auto missing = RunCommand({Bin("caliper-logviewer"), dir_.path() + "/none.log"});
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("cannot open " + dir_.path() + "/none.log"), std::string::npos)
      << missing.err;

  // a file with a malformed line: a warning naming file and line, then the window (SIGTERM ends)
  Process file_viewer({Bin("caliper-logviewer"), k::KnownSessionPath()}, dir_.path() + "/file.out");
  EXPECT_TRUE(WaitFor([&] { return file_viewer.Output().find("warning") != std::string::npos; },
                      seconds(10)));
  EXPECT_NE(file_viewer.Output().find("known_session.log:19: not a log record"), std::string::npos)
      << file_viewer.Output();
  file_viewer.Signal(SIGTERM);
  EXPECT_EQ(file_viewer.Wait(seconds(10)), 0) << file_viewer.Output();

  // live: SIGTERM closes cleanly, writes the session and unregisters the listener
  auto logger = StartLogger();
  ASSERT_TRUE(Send(1, 1));
  const std::string ini = dir_.path() + "/session.ini";
  Process viewer({Bin("caliper-logviewer"), "--nameservice", naming_->address(), "--session", ini,
                  "--geometry", "640x480+10+20"},
                 dir_.path() + "/viewer.out");
  EXPECT_TRUE(WaitFor(
      [&] { return viewer.Output().find("following logger0") != std::string::npos; }, seconds(20)))
      << viewer.Output();
  viewer.Signal(SIGTERM);
  EXPECT_EQ(viewer.Wait(seconds(10)), 0) << viewer.Output();
  const auto record = gui_session::ReadToolWindow(QString::fromStdString(ini), "log_viewer");
  EXPECT_EQ(record.geometry, QRect(10, 20, 640, 480));
  EXPECT_EQ(record.pid, viewer.pid());
  EXPECT_NE(record.window_id, 0u);
  ASSERT_TRUE(Send(2, 2));  // a listener left behind would fail now and be dropped by the logger
  std::this_thread::sleep_for(milliseconds(1500));
  EXPECT_EQ(SessionLog().find("dropping a log listener"), std::string::npos) << SessionLog();

  // the control: a killed viewer cannot unregister, and the logger notices
  Process killed({Bin("caliper-logviewer"), "--nameservice", naming_->address()},
                 dir_.path() + "/killed.out");
  EXPECT_TRUE(WaitFor(
      [&] { return killed.Output().find("following logger0") != std::string::npos; }, seconds(20)))
      << killed.Output();
  killed.Signal(SIGKILL);
  killed.Wait(seconds(5));
  ASSERT_TRUE(Send(3, 3));
  EXPECT_TRUE(
      WaitFor([&] { return SessionLog().find("dropping a log listener") != std::string::npos; },
              seconds(10)))
      << SessionLog();
}

}  // namespace
}  // namespace caliper::log_viewer
