#include "caliper/gui_session/tool_window.h"

#include <QCoreApplication>
#include <QEvent>
#include <QRegularExpression>
#include <QSettings>
#include <QTimer>
#include <QWidget>

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

void ToolWindow::Save() {
  if (session_file_.isEmpty()) return;
  QSettings st(session_file_, QSettings::IniFormat);
  st.beginGroup(tool_);
  st.setValue("geometry", FormatGeometry(window_->geometry()));
  st.setValue("window_id", static_cast<qulonglong>(window_->isVisible() ? window_->winId() : 0));
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
        Save();
        break;
      default:
        break;
    }
  }
  return QObject::eventFilter(watched, event);
}

}  // namespace caliper::gui_session
