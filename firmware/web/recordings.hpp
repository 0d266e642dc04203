// The recordings of record_dir as the page offers them: the pair folders (8 digits, recorder.hpp)
// and one pair as a tar archive (ustar) of its files. Only names of that form are accepted, so a
// request cannot reach a file outside record_dir.
#pragma once

#include <string>
#include <vector>

#include "recog/base/status.hpp"

namespace sh::fw::web {

// A pair folder's name: exactly 8 decimal digits.
bool IsPairName(const char* name);

// The complete pair folders of `record_dir` (their `done_file` written: the recorder writes
// result.json last), newest last (at most `limit`, the newest).
std::vector<std::string> ListPairs(const char* record_dir, size_t limit,
                                   const char* done_file = "result.json");

// The regular files of record_dir/pair as a ustar archive (pair/left.png, ...), at most
// kMaxArchiveBytes.
Status ArchivePair(const char* record_dir, const char* pair, std::string* tar);

// One ustar member: header block and the data padded to 512 bytes, appended to *tar.
void AppendTarMember(const std::string& name, const std::string& data, long long mtime_s,
                     std::string* tar);

}  // namespace sh::fw::web
