#pragma once
// The Log Viewer's window: the record table, the filter panel (priority, text or regular
// expression, time range, a tree of categories and components with check boxes; each filter
// hiding or highlighting), a status line saying whether the live service is connected, File >
// Open for a past session's log, copy and export of the selection. It reads a LogModel (which
// owns the records) and takes live records from a LogLink with a timer; it never calls CORBA.
//
// Session file (QSettings IniFormat, shared with the Main Window), group `log_viewer`:
//   geometry, window_id, pid  the window's record, kept by gui_session::ToolWindow (the Main
//                             Window reads it to place and arrange the tools)
//   min_priority, priority_mode
//   excluded_categories, category_mode, excluded_components, component_mode
//   text, regex, case_sensitive, text_mode
//   from_time_us, to_time_us, time_mode     (0: unbounded)
//   follow_tail, splitter, filter_splitter, columns
// Modes are `hide` or `highlight`. A value that is not understood keeps the default and is named
// on the status line (session_problem()).

#include <QMainWindow>
#include <QRect>
#include <QString>
#include <QStringList>
#include <map>
#include <memory>
#include <string>

#include "caliper/gui_session/tool_window.h"
#include "log_filter.h"
#include "log_link.h"
#include "log_model.h"

class QAction;
class QCheckBox;
class QCloseEvent;
class QComboBox;
class QDateTimeEdit;
class QLabel;
class QLineEdit;
class QSplitter;
class QTableView;
class QTimer;
class QTreeWidget;
class QTreeWidgetItem;

namespace caliper::log_viewer {

class LogViewerWindow : public QMainWindow {
 public:
  struct Options {
    LogLink::Options link;    ///< where the live service is
    QString session_file;     ///< settings shared with the Main Window; "" for none
    QRect geometry;           ///< --geometry (invalid: none): wins over the session's
    int poll_ms = 100;        ///< how often live records are taken in (one batch each time)
    int text_delay_ms = 250;  ///< typing in the text filter applies it after this pause
    int save_delay_ms = 500;  ///< moves, resizes and filter changes are saved after this pause
  };

  /// Restores geometry and filters from the session file when there is one. Neither follows the
  /// live service nor opens a file: call FollowLive() or OpenFile().
  explicit LogViewerWindow(Options options, QWidget* parent = nullptr);
  /// Unregisters from the live service.
  ~LogViewerWindow() override;

  /// Follows the live service from now on: the table is emptied first (unless `keep`: then the
  /// records shown stay, and those the service also holds are not repeated), then filled with
  /// what the service holds and what arrives.
  void FollowLive(bool keep = false);
  /// Shows a session log instead of the live service. Malformed lines are skipped and listed in
  /// problems(); false with `*error` set when the file cannot be read (the table is unchanged).
  bool OpenFile(const QString& path, QString* error = nullptr);
  /// Writes the selected rows (every shown row when none is selected) as a session log that
  /// OpenFile reads back; false with `*error` set on failure. Refuses to write over the file
  /// shown or the live logger's session log (a selection would replace what is not selected);
  /// a failed write leaves an existing file as it was.
  bool ExportTo(const QString& path, QString* error = nullptr);
  /// Copies the selected rows, tab-separated (time, priority, category, component, host,
  /// message), to the clipboard.
  void CopySelection();
  /// Writes the window record and the filters to the session file (closing does it too); no-op
  /// without one.
  void SaveSession();
  /// Takes in the live records that arrived and refreshes the status line (the timer calls it).
  void Poll();
  /// Applies the filter widgets now instead of after the typing pause.
  void ApplyFilters();
  /// The filters as the widgets set them.
  FilterSettings CurrentFilter() const;

  LogModel& model() { return *model_; }
  QTableView* table() const { return table_; }
  bool live() const { return link_ != nullptr; }
  /// The live connection's status (disconnected when not live).
  LinkStatus link_status() const;
  /// The file shown, or "" when live.
  const QString& file() const { return file_; }
  /// Messages about the malformed lines of the file opened last (`PATH:LINE: ...`).
  const QStringList& problems() const { return problems_; }
  /// What the session file held that was ignored (`FILE [log_viewer]: ignored KEY=VALUE, ...`),
  /// or ""; shown on the status line with the file's malformed lines.
  const QString& session_problem() const { return session_problem_; }

 protected:
  void closeEvent(QCloseEvent* event) override;
  bool eventFilter(QObject* watched, QEvent* event) override;

 private:
  QWidget* BuildFilterPanel();
  void BuildMenus();
  void RestoreSession();
  void ShowFilter(const FilterSettings& settings);
  void ScheduleApply(int delay_ms);
  void ScheduleSave();
  void ResetSources();
  void UpdateSources();
  void OnSourceChanged(QTreeWidgetItem* item);
  QTreeWidgetItem* CategoryItem(const std::string& prefix);
  void UpdateCounts();
  void UpdateStatus();
  void ShowProblems();
  void AfterAppend(size_t added);
  void SetTimeDefaults();
  std::vector<int> SelectedRows() const;
  void OpenFileDialog();
  void ExportDialog();

  Options options_;
  std::unique_ptr<LogLink> link_;
  LogModel* model_ = nullptr;
  QString file_;
  QStringList problems_;
  size_t malformed_ = 0;  ///< malformed lines in the file shown
  QString session_problem_;
  FilterSettings filter_;  ///< what the widgets last said (exclusions without a node included)
  bool updating_ = false;  ///< widgets are being set by the program, not the user

  QTableView* table_ = nullptr;
  QSplitter* splitter_ = nullptr;
  QSplitter* filter_splitter_ = nullptr;
  QComboBox* priority_ = nullptr;
  QComboBox* priority_mode_ = nullptr;
  QLineEdit* text_ = nullptr;
  QCheckBox* regex_ = nullptr;
  QCheckBox* case_sensitive_ = nullptr;
  QComboBox* text_mode_ = nullptr;
  QLabel* text_error_ = nullptr;
  QCheckBox* from_enabled_ = nullptr;
  QDateTimeEdit* from_ = nullptr;
  QCheckBox* to_enabled_ = nullptr;
  QDateTimeEdit* to_ = nullptr;
  QComboBox* time_mode_ = nullptr;
  QTreeWidget* sources_ = nullptr;
  QTreeWidgetItem* categories_root_ = nullptr;
  QTreeWidgetItem* components_root_ = nullptr;
  QComboBox* category_mode_ = nullptr;
  QComboBox* component_mode_ = nullptr;
  std::map<std::string, QTreeWidgetItem*> category_items_;   ///< dotted prefix -> node
  std::map<std::string, QTreeWidgetItem*> component_items_;  ///< instance -> node
  size_t categories_seen_ = 0;  ///< store categories already in the tree
  size_t components_seen_ = 0;
  QLabel* connection_ = nullptr;
  QLabel* counts_ = nullptr;
  QLabel* problems_label_ = nullptr;
  QAction* follow_tail_ = nullptr;
  QAction* show_filters_ = nullptr;  // the filter panel beside the table
  QTimer* poll_timer_ = nullptr;
  QTimer* apply_timer_ = nullptr;
  QTimer* save_timer_ = nullptr;  ///< filter changes; the window record saves itself
  gui_session::ToolWindow* tool_window_ = nullptr;
};

}  // namespace caliper::log_viewer
