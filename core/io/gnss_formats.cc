#include "core/io/gnss_formats.h"

namespace gins {
namespace {

constexpr const char* kQualityNames[kNumFixQualities] = {"fix", "float", "ppp", "dgps", "sbas", "single"};

}  // namespace

const char* FixQualityName(FixQuality q) { return kQualityNames[static_cast<int>(q)]; }

bool ParseFixQuality(const std::string& name, FixQuality* q) {
  for (int i = 0; i < kNumFixQualities; ++i) {
    if (name == kQualityNames[i]) {
      *q = static_cast<FixQuality>(i);
      return true;
    }
  }
  return false;
}

bool RecordSource::Accept(LogRecord* record, uint64_t line, FileIssues* issues, const char* quality, int leap_seconds) {
  InputIssue issue;
  if (CheckLogRecord(record, &issue) == LineParse::kDamaged) {
    issues->Damage(line, issue.reason.c_str(),
                   std::string("as a ") + record->info().token + " record: " + issue.detail);
    return false;
  }
  record->line = line;
  const double t = record->t();
  if (!file_.has_range) file_.t_first = t;
  file_.has_range = true;
  file_.t_last = t;
  ++file_.written;
  ++stats_.leap_seconds[leap_seconds];
  ++stats_.records[record->type_index()];
  if (record->is<GnssRecord>()) ++stats_.qualities[quality];
  return true;
}

}  // namespace gins
