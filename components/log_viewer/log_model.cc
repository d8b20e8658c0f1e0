#include "log_model.h"

#include <QBrush>
#include <QColor>
#include <QFont>

#include "caliper/core/system.h"

namespace caliper::log_viewer {

namespace {

QString Flat(const std::string& text) {
  QString s = QString::fromStdString(text);
  s.replace('\t', ' ');
  s.replace('\n', ' ');
  s.replace('\r', ' ');
  return s;
}

}  // namespace

LogModel::LogModel(QObject* parent) : QAbstractTableModel(parent) {
  view_.Apply(FilterSettings{}, store_);
}

size_t LogModel::Append(std::vector<logging::Record> records) {
  if (records.empty()) return 0;
  if (store_.size() + records.size() > max_records_) {
    // keep memory bounded: drop the oldest quarter in one reset rather than a row at a time
    beginResetModel();
    const size_t keep = max_records_ - max_records_ / 4;
    const size_t total = store_.size() + records.size();
    store_.DropOldest(std::min(store_.size(), total > keep ? total - keep : 0));
    if (records.size() > keep)
      records.erase(records.begin(), records.end() - static_cast<std::ptrdiff_t>(keep));
    store_.Append(std::move(records));
    view_.Reset();
    view_.Apply(view_.settings(), store_);
    shown_ = static_cast<int>(view_.rows().size());
    endResetModel();
    return static_cast<size_t>(shown_);
  }
  if (store_.Append(std::move(records)) == 0) return 0;
  const size_t added = view_.Update(store_);
  if (added == 0) return 0;
  beginInsertRows(QModelIndex(), shown_, shown_ + static_cast<int>(added) - 1);
  shown_ = static_cast<int>(view_.rows().size());
  endInsertRows();
  return added;
}

void LogModel::Replace(std::vector<logging::Record> records) {
  beginResetModel();
  store_.Clear();
  view_.Reset();
  store_.Append(std::move(records));
  view_.Apply(view_.settings(), store_);
  shown_ = static_cast<int>(view_.rows().size());
  endResetModel();
}

void LogModel::SetFilter(const FilterSettings& settings) {
  beginResetModel();
  view_.Apply(settings, store_);
  shown_ = static_cast<int>(view_.rows().size());
  endResetModel();
}

const Entry& LogModel::EntryAt(int row) const {
  return store_.entry(view_.rows()[static_cast<size_t>(row)]);
}

logging::Record LogModel::RecordAt(int row) const {
  return store_.record(view_.rows()[static_cast<size_t>(row)]);
}

std::vector<logging::Record> LogModel::RecordsAt(const std::vector<int>& rows) const {
  std::vector<logging::Record> out;
  out.reserve(rows.size());
  for (int row : rows)
    if (row >= 0 && row < shown_) out.push_back(RecordAt(row));
  return out;
}

QString LogModel::CellText(int row, int column) const {
  const Entry& e = EntryAt(row);
  switch (column) {
    case kTimeColumn:
      return QString::fromStdString(core::FormatTime(e.time_us));
    case kPriorityColumn:
      return QString::fromStdString(logging::PriorityName(e.priority));
    case kCategoryColumn:
      return Flat(store_.category(e));
    case kComponentColumn:
      return Flat(store_.component(e));
    case kHostColumn:
      return Flat(store_.host(e));
    case kMessageColumn:
      return Flat(e.message);
    default:
      return QString();
  }
}

QString LogModel::CopyText(const std::vector<int>& rows) const {
  QString text;
  for (int row : rows) {
    if (row < 0 || row >= shown_) continue;
    for (int c = 0; c < kColumnCount; ++c) {
      if (c > 0) text += '\t';
      text += CellText(row, c);
    }
    text += '\n';
  }
  return text;
}

int LogModel::rowCount(const QModelIndex& parent) const { return parent.isValid() ? 0 : shown_; }

int LogModel::columnCount(const QModelIndex& parent) const {
  return parent.isValid() ? 0 : kColumnCount;
}

QVariant LogModel::data(const QModelIndex& index, int role) const {
  if (!index.isValid() || index.row() >= shown_) return QVariant();
  const int row = index.row();
  switch (role) {
    case Qt::DisplayRole:
      // the time of day in the table (the date in its tooltip, copies and exports)
      return index.column() == kTimeColumn ? CellText(row, kTimeColumn).mid(11)
                                           : CellText(row, index.column());
    case Qt::ToolTipRole:
      if (index.column() == kTimeColumn) return CellText(row, kTimeColumn);
      return index.column() == kMessageColumn
                 ? QVariant(QString::fromStdString(EntryAt(row).message))
                 : QVariant();
    case Qt::ForegroundRole: {
      const int p = EntryAt(row).priority;
      if (p <= logging::kError) return QBrush(QColor(200, 0, 0));      // errors: red
      if (p <= logging::kWarn) return QBrush(QColor(215, 110, 0));     // warnings: orange
      if (p >= logging::kDebug) return QBrush(QColor(110, 110, 110));  // debug: grey
      return QVariant();
    }
    case Qt::BackgroundRole:
      return view_.highlighted(static_cast<size_t>(row)) ? QBrush(QColor(255, 236, 120))
                                                         : QVariant();
    case Qt::FontRole:
      if (EntryAt(row).priority <= logging::kCrit) {
        QFont bold;
        bold.setBold(true);
        return bold;
      }
      return QVariant();
    default:
      return QVariant();
  }
}

QVariant LogModel::headerData(int section, Qt::Orientation orientation, int role) const {
  if (orientation != Qt::Horizontal || role != Qt::DisplayRole) return QVariant();
  switch (section) {
    case kTimeColumn:
      return QStringLiteral("Time");
    case kPriorityColumn:
      return QStringLiteral("Priority");
    case kCategoryColumn:
      return QStringLiteral("Category");
    case kComponentColumn:
      return QStringLiteral("Component");
    case kHostColumn:
      return QStringLiteral("Host");
    case kMessageColumn:
      return QStringLiteral("Message");
    default:
      return QVariant();
  }
}

}  // namespace caliper::log_viewer
