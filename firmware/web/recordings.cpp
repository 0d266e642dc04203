#include "firmware/web/recordings.hpp"

#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>

#include "firmware/web/web_limits.hpp"

namespace sh::fw::web {

bool IsPairName(const char* name) {
  if (name == nullptr) return false;
  int n = 0;
  for (; name[n] != '\0'; ++n) {
    if (n >= 8 || name[n] < '0' || name[n] > '9') return false;
  }
  return n == 8;
}

std::vector<std::string> ListPairs(const char* record_dir, size_t limit, const char* done_file) {
  std::vector<std::string> names;
  DIR* dir = opendir(record_dir);
  if (dir == nullptr) return names;
  while (const dirent* e = readdir(dir)) {
    // A pair without its last file is still being written.
    if (IsPairName(e->d_name) &&
        access((std::string(record_dir) + "/" + e->d_name + "/" + done_file).c_str(), R_OK) == 0) {
      names.emplace_back(e->d_name);
    }
  }
  closedir(dir);
  std::sort(names.begin(), names.end());
  if (names.size() > limit) names.erase(names.begin(), names.end() - static_cast<long>(limit));
  return names;
}

void AppendTarMember(const std::string& name, const std::string& data, long long mtime_s,
                     std::string* tar) {
  char h[512] = {};
  std::snprintf(h, 100, "%s", name.c_str());
  std::snprintf(h + 100, 8, "%07o", 0644);
  std::snprintf(h + 108, 8, "%07o", 0);
  std::snprintf(h + 116, 8, "%07o", 0);
  std::snprintf(h + 124, 12, "%011llo", static_cast<unsigned long long>(data.size()));
  std::snprintf(h + 136, 12, "%011llo", static_cast<unsigned long long>(mtime_s));
  h[156] = '0';
  std::memcpy(h + 257, "ustar", 6);  // with its NUL
  h[263] = h[264] = '0';             // version "00", not NUL-terminated
  std::memset(h + 148, ' ', 8);      // the checksum counts its own field as spaces
  unsigned sum = 0;
  for (unsigned char c : h) sum += c;
  std::snprintf(h + 148, 8, "%06o", sum);
  h[155] = ' ';
  tar->append(h, sizeof(h));
  tar->append(data);
  tar->append((512 - data.size() % 512) % 512, '\0');
}

Status ArchivePair(const char* record_dir, const char* pair, std::string* tar) {
  if (!IsPairName(pair)) {
    return Status::Error(StatusCode::kInvalidArgument, "a recording is named by 8 digits");
  }
  const std::string folder = std::string(record_dir) + "/" + pair;
  DIR* dir = opendir(folder.c_str());
  if (dir == nullptr) return Status::Error(StatusCode::kNotFound, "no recording %s", pair);
  std::vector<std::string> files;
  while (const dirent* e = readdir(dir)) {
    if (e->d_name[0] != '.') files.emplace_back(e->d_name);
  }
  closedir(dir);
  std::sort(files.begin(), files.end());
  tar->clear();
  for (const std::string& f : files) {
    std::string path = folder;
    path += '/';
    path += f;
    struct stat st {};
    // Regular files only, not links (that could point out of record_dir).
    if (lstat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) continue;
    if (tar->size() + static_cast<size_t>(st.st_size) + 1024 > kMaxArchiveBytes) {
      return Status::Error(StatusCode::kResourceExhausted, "recording %s is over %zu bytes", pair,
                           kMaxArchiveBytes);
    }
    FILE* in = std::fopen(path.c_str(), "rb");
    if (in == nullptr) continue;
    std::string data(static_cast<size_t>(st.st_size), '\0');
    const size_t got = std::fread(&data[0], 1, data.size(), in);
    std::fclose(in);
    data.resize(got);
    AppendTarMember(std::string(pair) + "/" + f, data, st.st_mtime, tar);
  }
  tar->append(1024, '\0');  // the end of the archive
  return Status::Ok();
}

}  // namespace sh::fw::web
