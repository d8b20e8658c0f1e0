#include "caliper/gui_session/tool_window.h"

#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>

#include <QApplication>
#include <QCoreApplication>
#include <QEvent>
#include <QRegularExpression>
#include <QSettings>
#include <QSocketNotifier>
#include <QTimer>
#include <QWidget>

#include "caliper/core/arguments.h"

namespace caliper::gui_session {

bool ParseGeometry(const QString& text, QRect* rect) {
  static const QRegularExpression kPattern(R"(^(\d+)x(\d+)\+(-?\d+)\+(-?\d+)$)");
  const QRegularExpressionMatch m = kPattern.match(text.trimmed());
  if (!m.hasMatch()) return false;
  const int w = m.captured(1).toInt();
  const int h = m.captured(2).toInt();
  if (w <= 0 || h <= 0) return false;
  *rect = QRect(m.captured(3).toInt(), m.captured(4).toInt(), w, h);
  return true;
}

QString FormatGeometry(const QRect& rect) {
  return QString("%1x%2+%3+%4").arg(rect.width()).arg(rect.height()).arg(rect.x()).arg(rect.y());
}

ToolWindowRecord ReadToolWindow(const QString& session_file, const QString& tool) {
  ToolWindowRecord record;
  if (session_file.isEmpty()) return record;
  QSettings st(session_file, QSettings::IniFormat);
  st.beginGroup(tool);
  QRect rect;
  if (ParseGeometry(st.value("geometry").toString(), &rect)) record.geometry = rect;
  record.window_id = st.value("window_id", 0).toULongLong();
  record.pid = st.value("pid", 0).toLongLong();
  return record;
}

ToolWindow::ToolWindow(QWidget* window, QString tool, QString session_file, int save_delay_ms)
    : QObject(window),
      window_(window),
      tool_(std::move(tool)),
      session_file_(std::move(session_file)),
      save_timer_(new QTimer(this)) {
  save_timer_->setSingleShot(true);
  save_timer_->setInterval(save_delay_ms);
  connect(save_timer_, &QTimer::timeout, this, [this] { Save(); });
  window_->installEventFilter(this);
}

QRect ToolWindow::Restore(const QRect& explicit_geometry) {
  QRect rect = explicit_geometry;
  if (!rect.isValid()) rect = ReadToolWindow(session_file_, tool_).geometry;
  if (rect.isValid()) window_->setGeometry(rect);
  return rect;
}

void ToolWindow::Save(bool closing) {
  if (session_file_.isEmpty()) return;
  QSettings st(session_file_, QSettings::IniFormat);
  st.beginGroup(tool_);
  st.setValue("geometry", FormatGeometry(window_->geometry()));
  // a closing window is no longer there to be moved
  const bool shown = window_->isVisible() && !closing;
  st.setValue("window_id", static_cast<qulonglong>(shown ? window_->winId() : 0));
  st.setValue("pid", QCoreApplication::applicationPid());
  st.endGroup();
  st.sync();
}

bool ToolWindow::eventFilter(QObject* watched, QEvent* event) {
  if (watched == window_) {
    switch (event->type()) {
      case QEvent::Show:
      case QEvent::Move:
      case QEvent::Resize:
        save_timer_->start();
        break;
      case QEvent::Close:
        save_timer_->stop();
        Save(/*closing=*/true);
        break;
      default:
        break;
    }
  }
  return QObject::eventFilter(watched, event);
}

namespace {

int signal_socket[2] = {-1, -1};  // [0] written by the handler, [1] read by the event loop

void OnTerminationSignal(int) {
  const int saved = errno;  // the interrupted code may be looking at errno
  const char c = 1;
  [[maybe_unused]] const auto n = ::write(signal_socket[0], &c, 1);  // non-blocking
  errno = saved;
}

}  // namespace

bool IsQtOptionWithValue(const std::string& option) {
  for (const char* o : {"-platform", "-platformpluginpath", "-platformtheme", "-plugin",
                        "-qwindowgeometry", "-qwindowicon", "-qwindowtitle", "-style",
                        "-stylesheet", "-display", "-geometry", "-title", "-name"})
    if (option == o) return true;
  return false;
}

std::string ToolArguments::Value(const std::string& option, const std::string& fallback) const {
  const auto it = values.find(option);
  return it == values.end() || it->second.empty() ? fallback : it->second.back();
}

ToolArguments SplitToolArguments(int argc, char** argv, const std::set<std::string>& valued,
                                 const std::set<std::string>& flags) {
  core::ArgumentSpec spec;
  spec.valued = valued;
  spec.flags = flags;
  // Qt's own (-platform offscreen, -style fusion ...): what Qt does not take stays in
  // QApplication::arguments() for the tool to refuse
  spec.pass = [](const std::string& word) {
    if (word.size() < 2 || word[0] != '-' || word[1] == '-') return 0;
    return IsQtOptionWithValue(word) ? 2 : 1;
  };
  const core::Arguments parsed = core::ParseArguments({argv + 1, argv + argc}, spec);
  ToolArguments out;
  for (const auto& [option, value] : parsed.options) {
    if (flags.count(option) != 0)
      out.flags.insert(option);
    else
      out.values[option].push_back(value);
  }
  out.positional = parsed.positional;
  out.help = parsed.help;
  out.error = parsed.Error();
  out.qt_argv.push_back(argv[0]);
  for (const size_t i : parsed.passed) out.qt_argv.push_back(argv[i + 1]);
  out.qt_argv.push_back(nullptr);
  return out;
}

void CloseOnTerminationSignals(QWidget* window) {
  if (signal_socket[0] >= 0 ||
      ::socketpair(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0, signal_socket) != 0)
    return;
  auto* notifier = new QSocketNotifier(signal_socket[1], QSocketNotifier::Read, window);
  QObject::connect(notifier, &QSocketNotifier::activated, window, [window] {
    char c;
    [[maybe_unused]] const auto n = ::read(signal_socket[1], &c, 1);
    window->close();
    QApplication::quit();
  });
  struct sigaction sa = {};
  sa.sa_handler = OnTerminationSignal;
  sigemptyset(&sa.sa_mask);
  // a second Ctrl-C while the first one's shutdown hangs ends the process the default way
  sa.sa_flags = SA_RESTART | SA_RESETHAND;
  sigaction(SIGTERM, &sa, nullptr);
  sigaction(SIGINT, &sa, nullptr);
}

}  // namespace caliper::gui_session
