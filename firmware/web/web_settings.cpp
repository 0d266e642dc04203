#include "firmware/web/web_settings.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>

#include "firmware/web/json_writer.hpp"
#include "tables/input_file.hpp"

namespace sh::fw::web {
namespace {

ConfigKeyId IdOf(const ConfigKey& key) { return static_cast<ConfigKeyId>(&key - ConfigKeys()); }

bool SameValue(const ConfigKey& key, const FwConfig& a, const FwConfig& b) {
  const auto* pa = reinterpret_cast<const uint8_t*>(&a) + key.offset;
  const auto* pb = reinterpret_cast<const uint8_t*>(&b) + key.offset;
  if (key.type == KeyType::kText) {
    return std::strncmp(reinterpret_cast<const char*>(pa), reinterpret_cast<const char*>(pb),
                        key.size) == 0;
  }
  return std::memcmp(pa, pb, key.size) == 0;
}

bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\r'; }

// The key a line sets (`key = ...`), or an empty string.
std::string LineKey(const std::string& line) {
  size_t p = 0;
  while (p < line.size() && IsSpace(line[p])) ++p;
  const size_t start = p;
  while (p < line.size() && line[p] != '=' && line[p] != '#' && !IsSpace(line[p])) ++p;
  const std::string key = line.substr(start, p - start);
  while (p < line.size() && IsSpace(line[p])) ++p;
  return p < line.size() && line[p] == '=' ? key : std::string();
}

}  // namespace

bool KeyLockedFromPage(ConfigKeyId key) {
  return key == ConfigKeyId::backend || key == ConfigKeyId::http_bind ||
         key == ConfigKeyId::http_port || key == ConfigKeyId::http_password ||
         key == ConfigKeyId::http_password_file;
}

bool KeyIsSecret(ConfigKeyId key) { return key == ConfigKeyId::http_password; }

WebSettings::WebSettings(const FwConfig& running, const char* path)
    : current_(running), path_(path != nullptr ? path : "") {}

std::string WebSettings::Json() const {
  JsonWriter j;
  j.BeginObject().Key("file").String(path_.c_str()).Key("keys").BeginArray();
  for (size_t i = 0; i < ConfigKeyCount(); ++i) {
    const ConfigKey& k = ConfigKeys()[i];
    const ConfigKeyId id = IdOf(k);
    char type[192], value[kConfigPathMax];
    FormatConfigType(k, type, sizeof(type));
    FormatConfigValue(k, current_, value, sizeof(value));
    j.BeginObject().Key("name").String(k.name).Key("type").String(type).Key("help").String(k.help);
    j.Key("value").String(KeyIsSecret(id) ? (value[0] ? "(set)" : "") : value);
    const bool runtime = id == ConfigKeyId::budget_ms || id == ConfigKeyId::free_run_dhz ||
                         id == ConfigKeyId::heartbeat_ms || id == ConfigKeyId::model_mask;
    j.Key("runtime").Bool(runtime).Key("locked").Bool(KeyLockedFromPage(id));
    j.Key("edited").Bool(edited_.Has(i)).EndObject();
  }
  j.EndArray().EndObject();
  return j.text();
}

Status WebSettings::Change(const char* text, size_t bytes, WebTarget* target, std::string* report) {
  // Large: off the server thread's stack.
  std::unique_ptr<FwConfig> next = std::make_unique<FwConfig>(current_);
  next->given = ConfigKeySet();  // a key given twice in this text is the file's error too
  SH_RETURN_IF_ERROR(ParseConfig(text, bytes, next.get()));
  for (size_t i = 0; i < ConfigKeyCount(); ++i) {
    if (next->given.Has(i) && KeyLockedFromPage(static_cast<ConfigKeyId>(i))) {
      return Status::Error(StatusCode::kFailedPrecondition,
                           "key '%s' is changed in the configuration file only",
                           ConfigKeys()[i].name);
    }
  }
  const ConfigKeySet named = next->given;
  next->given = current_.given;
  for (size_t i = 0; i < ConfigKeyCount(); ++i) {
    if (named.Has(i)) next->given.Add(i);
  }
  SH_RETURN_IF_ERROR(ValidateConfig(*next));
  report->clear();
  for (size_t i = 0; i < ConfigKeyCount(); ++i) {
    const ConfigKey& k = ConfigKeys()[i];
    if (!named.Has(i) || SameValue(k, current_, *next)) continue;
    const Result<bool> applied = target->ApplySetting(static_cast<ConfigKeyId>(i), *next);
    if (!applied.ok()) return applied.status();
    report->append(k.name).append(*applied ? ": applied\n" : ": at the next start\n");
  }
  for (size_t i = 0; i < ConfigKeyCount(); ++i) {
    if (named.Has(i) && !SameValue(ConfigKeys()[i], current_, *next)) edited_.Add(i);
  }
  current_ = *next;
  if (report->empty()) report->assign("no value changed\n");
  return Status::Ok();
}

std::string RewriteConfigText(const std::string& original, const FwConfig& config,
                              const ConfigKeySet& edited) {
  ConfigKeySet written;
  std::string out;
  size_t pos = 0;
  while (pos < original.size()) {
    size_t end = original.find('\n', pos);
    if (end == std::string::npos) end = original.size();
    std::string line = original.substr(pos, end - pos);
    pos = end + 1;
    const ConfigKey* key = FindConfigKey(LineKey(line).c_str());
    if (key != nullptr) {
      const size_t id = static_cast<size_t>(key - ConfigKeys());
      if (edited.Has(id)) {
        char value[kConfigPathMax];
        FormatConfigValue(*key, config, value, sizeof(value));
        const size_t hash = line.find('#');
        const std::string comment = hash != std::string::npos ? "  " + line.substr(hash) : "";
        line = std::string(key->name) + " = " + value + comment;
        written.Add(id);
      }
    }
    out += line;
    out += '\n';
  }
  for (size_t i = 0; i < ConfigKeyCount(); ++i) {
    if (!edited.Has(i) || written.Has(i)) continue;
    char value[kConfigPathMax];
    FormatConfigValue(ConfigKeys()[i], config, value, sizeof(value));
    out += std::string(ConfigKeys()[i].name) + " = " + value + "\n";
  }
  return out;
}

Status ReplaceFileAtomically(const char* path, const std::string& text) {
  const std::string temp = std::string(path) + ".new";
  const int fd = open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    return Status::Error(StatusCode::kUnavailable, "cannot write %s: %s", temp.c_str(),
                         std::strerror(errno));
  }
  size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = write(fd, text.data() + done, text.size() - done);
    if (n <= 0) break;
    done += static_cast<size_t>(n);
  }
  const bool written = done == text.size() && fsync(fd) == 0;
  const int error = errno;
  close(fd);
  if (!written || rename(temp.c_str(), path) != 0) {
    const int e = written ? errno : error;
    unlink(temp.c_str());
    return Status::Error(StatusCode::kUnavailable, "cannot replace %s: %s", path, std::strerror(e));
  }
  return Status::Ok();
}

Status WebSettings::Save() {
  if (path_.empty()) {
    return Status::Error(StatusCode::kFailedPrecondition,
                         "the firmware was started without a configuration file (--config): "
                         "nothing to write back");
  }
  static char text[kMaxConfigFileBytes];
  size_t n = 0;
  SH_RETURN_IF_ERROR(ReadInputFile(path_.c_str(), "config", text, sizeof(text), &n));
  return ReplaceFileAtomically(path_.c_str(),
                               RewriteConfigText(std::string(text, n), current_, edited_));
}

}  // namespace sh::fw::web
