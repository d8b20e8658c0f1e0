#pragma once
// The Log Viewer's table model: a QAbstractTableModel over a RecordStore and the LogView of its
// filters. It owns both and is the only one to change them, so that every change is announced to
// the views (appends as one beginInsertRows batch, filter changes as a reset). No widget per row.

#include <QAbstractTableModel>
#include <QString>
#include <vector>

#include "caliper/logging/record.h"
#include "log_filter.h"
#include "record_store.h"

namespace caliper::log_viewer {

class LogModel : public QAbstractTableModel {
 public:
  enum Column : int {
    kTimeColumn = 0,
    kPriorityColumn,
    kCategoryColumn,
    kComponentColumn,
    kHostColumn,
    kMessageColumn,
    kColumnCount
  };

  explicit LogModel(QObject* parent = nullptr);

  /// Appends the records not seen before; the rows the filters show are inserted in one batch.
  /// Beyond max_records() the oldest quarter is dropped (a model reset). Returns the rows added.
  size_t Append(std::vector<logging::Record> records);
  /// Replaces every record (a file was opened): a model reset.
  void Replace(std::vector<logging::Record> records);
  /// New filter settings: a model reset.
  void SetFilter(const FilterSettings& settings);

  const RecordStore& store() const { return store_; }
  const LogView& view() const { return view_; }
  /// The record shown in `row`, as the store keeps it.
  const Entry& EntryAt(int row) const;
  /// The record shown in `row` (a copy with its names).
  logging::Record RecordAt(int row) const;
  /// The records shown in `rows` (indices of this model), in the given order.
  std::vector<logging::Record> RecordsAt(const std::vector<int>& rows) const;
  /// The shown columns of `rows` as tab-separated lines (tabs and newlines in fields as spaces).
  QString CopyText(const std::vector<int>& rows) const;

  /// Records kept at most (1,000,000 by default).
  size_t max_records() const { return max_records_; }
  void set_max_records(size_t n) { max_records_ = n; }

  int rowCount(const QModelIndex& parent = QModelIndex()) const override;
  int columnCount(const QModelIndex& parent = QModelIndex()) const override;
  QVariant data(const QModelIndex& index, int role = Qt::DisplayRole) const override;
  QVariant headerData(int section, Qt::Orientation orientation,
                      int role = Qt::DisplayRole) const override;

  /// The text of one cell.
  QString CellText(int row, int column) const;

 private:
  RecordStore store_;
  LogView view_;
  int shown_ = 0;  ///< rows announced to the views (view_.rows() may be ahead inside a change)
  size_t max_records_ = 1000000;
};

}  // namespace caliper::log_viewer
