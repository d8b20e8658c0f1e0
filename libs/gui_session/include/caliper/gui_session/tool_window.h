#pragma once
// A tool's window in the GUI session. The Main Window and its tools (renderer, plotter, log
// viewer) are separate processes sharing one session file (QSettings, INI format): each tool keeps
// its own group `<tool>/` there: its window geometry, its native window id and its process id.
// The Main Window reads these records to restore and to arrange the tools' windows.

#include <QObject>
#include <QRect>
#include <QString>
#include <map>
#include <set>
#include <string>
#include <vector>

class QTimer;
class QWidget;

namespace caliper::gui_session {

/// Parses an X11-style geometry "WIDTHxHEIGHT+X+Y" (X and Y may be negative: "+-10");
/// false when `text` is not one.
bool ParseGeometry(const QString& text, QRect* rect);
/// The inverse of ParseGeometry.
QString FormatGeometry(const QRect& rect);

/// What a tool last wrote about its window into the session file.
struct ToolWindowRecord {
  QRect geometry;            ///< the window's client area on the screen [px]; invalid when none
  unsigned long long window_id = 0;  ///< native window (X11 window id); 0 when not shown or closed
  long long pid = 0;         ///< the tool's process id; 0 when it has not run
};

/// Reads `<tool>/geometry`, `<tool>/window_id`, `<tool>/pid` from `session_file`.
ToolWindowRecord ReadToolWindow(const QString& session_file, const QString& tool);

/// Keeps one top-level window's record in the session file: restores its geometry before it is
/// shown, writes its window and process ids once shown, its geometry whenever it moves or is
/// resized (at most every `save_delay_ms`) and when it closes. With an empty session file it only
/// applies an explicit geometry.
class ToolWindow : public QObject {
 public:
  ToolWindow(QWidget* window, QString tool, QString session_file, int save_delay_ms = 300);

  /// Call before showing the window: `explicit_geometry` when valid, else the stored geometry.
  /// Returns the geometry applied (invalid when there was none).
  QRect Restore(const QRect& explicit_geometry = QRect());
  /// Writes the record now; `closing` records that the window is going away (no window id).
  void Save(bool closing = false);

  const QString& session_file() const { return session_file_; }
  const QString& tool() const { return tool_; }

 protected:
  bool eventFilter(QObject* watched, QEvent* event) override;

 private:
  QWidget* window_;
  QString tool_;
  QString session_file_;
  QTimer* save_timer_;
};

}  // namespace caliper::gui_session

namespace caliper::gui_session {

/// True for Qt's own command-line options that take a value (-platform, -style, -geometry, ...):
/// a tool that reads its options before QApplication passes these, and their values, through.
bool IsQtOptionWithValue(const std::string& option);

/// A GUI tool's command line taken apart before QApplication sees it: Qt would take `--session`
/// for itself, and `--help` must work without a display.
struct ToolArguments {
  std::map<std::string, std::vector<std::string>> values;  ///< --option VALUE, every occurrence
  std::set<std::string> flags;                              ///< --flag given
  std::vector<std::string> positional;                      ///< the other words, in order
  std::vector<char*> qt_argv;  ///< argv[0] and Qt's own options (-platform NAME, ...), then null
  bool help = false;           ///< --help or -h
  std::string error;           ///< what is wrong with the line ("" when nothing)

  int qt_argc() const { return static_cast<int>(qt_argv.size()) - 1; }
  /// The last value of `option`, or `fallback`.
  std::string Value(const std::string& option, const std::string& fallback = "") const;
};

/// Splits argv with core::ParseArguments: `valued` options take the next word, `flags` none;
/// single-dash words go to Qt (with the next word for the options IsQtOptionWithValue names).
ToolArguments SplitToolArguments(int argc, char** argv, const std::set<std::string>& valued,
                                 const std::set<std::string>& flags);

/// SIGINT and SIGTERM close `window` (which saves what it saves when closed) and quit the event
/// loop. The handlers only write a byte to a socket; the window is closed from the event loop, so
/// a signal that arrives before the loop runs is acted upon once it does. Call once per process.
void CloseOnTerminationSignals(QWidget* window);

}  // namespace caliper::gui_session
