// A tool's window record in the session file: geometry strings, restoring, and the record written
// when the window is shown, moved and closed. Widgets on the offscreen platform.
#include "caliper/gui_session/tool_window.h"

#include <gtest/gtest.h>

#include <QApplication>
#include <QDir>
#include <QElapsedTimer>
#include <QSettings>
#include <QTemporaryDir>
#include <QWidget>
#include <functional>

namespace caliper::gui_session {
namespace {

QApplication& App() {
  static int argc = 1;
  static char name[] = "tool_window_test";
  static char* argv[] = {name, nullptr};
  static QApplication app(argc, argv);
  return app;
}

bool WaitFor(const std::function<bool()>& condition) {
  QElapsedTimer t;
  t.start();
  while (t.elapsed() < 3000) {
    QApplication::processEvents(QEventLoop::AllEvents, 20);
    if (condition()) return true;
  }
  return condition();
}

TEST(Geometry, ParsesAndFormatsX11Geometries) {
  QRect r;
  ASSERT_TRUE(ParseGeometry("640x480+10+20", &r));
  EXPECT_EQ(r, QRect(10, 20, 640, 480));
  ASSERT_TRUE(ParseGeometry(" 300x200+-15+-4 ", &r));
  EXPECT_EQ(r, QRect(-15, -4, 300, 200));
  EXPECT_EQ(FormatGeometry(r), "300x200+-15+-4");
  ASSERT_TRUE(ParseGeometry(FormatGeometry(QRect(7, 8, 9, 10)), &r));
  EXPECT_EQ(r, QRect(7, 8, 9, 10));
}

TEST(Geometry, RejectsWhatIsNotOne) {
  QRect r(1, 2, 3, 4);
  for (const char* bad : {"", "640x480", "640x480+10", "0x480+0+0", "640x0+0+0", "ax480+0+0",
                          "640*480+0+0", "640x480+1+2+3"})
    EXPECT_FALSE(ParseGeometry(bad, &r)) << bad;
  EXPECT_EQ(r, QRect(1, 2, 3, 4)) << "left alone on failure";
}

TEST(ToolWindow, WritesTheShownWindowItsMovesAndItsClose) {
  App();
  QTemporaryDir dir;
  const QString file = dir.filePath("session.ini");
  QWidget widget;
  ToolWindow tool(&widget, "plotter", file, 20);
  EXPECT_FALSE(tool.Restore().isValid()) << "nothing stored yet";
  EXPECT_FALSE(ReadToolWindow(file, "plotter").geometry.isValid());
  EXPECT_EQ(tool.Restore(QRect(30, 40, 320, 240)), QRect(30, 40, 320, 240));
  widget.show();
  ToolWindowRecord record;
  ASSERT_TRUE(WaitFor([&] {
    record = ReadToolWindow(file, "plotter");
    return record.window_id != 0;
  }));
  EXPECT_EQ(record.geometry, QRect(30, 40, 320, 240));
  EXPECT_EQ(record.pid, QCoreApplication::applicationPid());
  EXPECT_EQ(record.window_id, static_cast<unsigned long long>(widget.winId()));

  widget.setGeometry(50, 60, 400, 300);
  EXPECT_TRUE(WaitFor([&] { return ReadToolWindow(file, "plotter").geometry == QRect(50, 60, 400, 300); }));
  widget.resize(410, 310);
  widget.close();  // written at once, without waiting for the timer
  EXPECT_EQ(ReadToolWindow(file, "plotter").geometry, QRect(50, 60, 410, 310));
  EXPECT_EQ(ReadToolWindow(file, "plotter").window_id, 0u) << "a closed window cannot be moved";
  EXPECT_FALSE(ReadToolWindow(file, "renderer").geometry.isValid()) << "other tools untouched";

  // the next start restores it; an explicit geometry wins
  QWidget next;
  ToolWindow again(&next, "plotter", file, 20);
  EXPECT_EQ(again.Restore(), QRect(50, 60, 410, 310));
  EXPECT_EQ(next.geometry(), QRect(50, 60, 410, 310));
  EXPECT_EQ(again.Restore(QRect(1, 2, 300, 200)), QRect(1, 2, 300, 200));
}

TEST(ToolWindow, KeepsOtherKeysOfTheSharedFile) {
  App();
  QTemporaryDir dir;
  const QString file = dir.filePath("session.ini");
  {
    QSettings st(file, QSettings::IniFormat);
    st.setValue("window/geometry", QRect(0, 0, 800, 600));
    st.setValue("tools/open", QStringList{"plotter"});
  }
  QWidget widget;
  ToolWindow tool(&widget, "plotter", file, 20);
  tool.Restore(QRect(5, 6, 200, 100));
  tool.Save();
  QSettings st(file, QSettings::IniFormat);
  EXPECT_EQ(st.value("window/geometry").toRect(), QRect(0, 0, 800, 600));
  EXPECT_EQ(st.value("tools/open").toStringList(), QStringList{"plotter"});
  EXPECT_EQ(st.value("plotter/geometry").toString(), "200x100+5+6");
}

TEST(ToolWindow, WithoutASessionFileOnlyAppliesTheGeometry) {
  App();
  QWidget widget;
  ToolWindow tool(&widget, "renderer", QString(), 20);
  EXPECT_EQ(tool.Restore(QRect(3, 4, 100, 80)), QRect(3, 4, 100, 80));
  EXPECT_EQ(widget.geometry(), QRect(3, 4, 100, 80));
  // nothing is written anywhere: not even a file with an empty name in the working directory
  QTemporaryDir dir;
  const QString before = QDir::currentPath();
  ASSERT_TRUE(QDir::setCurrent(dir.path()));
  tool.Save();
  widget.show();
  widget.close();
  const QStringList written = QDir(dir.path()).entryList(QDir::AllEntries | QDir::NoDotAndDotDot |
                                                          QDir::Hidden);
  QDir::setCurrent(before);
  EXPECT_TRUE(written.isEmpty()) << written.join(", ").toStdString();
}

}  // namespace
}  // namespace caliper::gui_session
