// The command registry and option parsing shared by stereohash and stereohash-cv.
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "tools/command.hpp"

namespace sh::tools {
namespace {

constexpr int kMaxCommands = 32;
Command g_commands[kMaxCommands];
int g_count = 0;

}  // namespace

bool NextOption(const char* command, int argc, char** argv, void (*print_help)(), int* i,
                const char** option, const char** value, int* exit_code) {
  *option = argv[*i];
  if (std::strcmp(*option, "--help") == 0 || std::strcmp(*option, "-h") == 0) {
    print_help();
    *exit_code = 0;
    return false;
  }
  if (*i + 1 >= argc) {
    // Every option of these commands takes a value: a last word without one is either a
    // misspelt option or a value left out, and the message says both.
    std::fprintf(stderr, "stereohash %s: %s is not an option, or needs a value (see --help)\n",
                 command, *option);
    *exit_code = 2;
    return false;
  }
  // A second value would silently replace the first.
  if (std::strcmp(*option, "--set") != 0) {
    for (int j = 1; j < *i; ++j) {
      if (std::strcmp(argv[j], *option) == 0 && j + 1 < argc) {
        std::fprintf(stderr, "stereohash %s: %s given twice ('%s' and '%s'); give it once\n",
                     command, *option, argv[j + 1], argv[*i + 1]);
        *exit_code = 2;
        return false;
      }
    }
  }
  *value = argv[++*i];
  return true;
}

void RegisterCommand(const Command& command) {
  if (g_count < kMaxCommands) g_commands[g_count++] = command;
}

const Command* FindCommand(const char* name) {
  for (int i = 0; i < g_count; ++i) {
    if (std::strcmp(g_commands[i].name, name) == 0) return &g_commands[i];
  }
  return nullptr;
}

void ListCommands(void (*print)(const Command&)) {
  // Alphabetical, independent of static-initialisation order.
  bool printed[kMaxCommands] = {};
  for (int n = 0; n < g_count; ++n) {
    int best = -1;
    for (int i = 0; i < g_count; ++i) {
      if (!printed[i] && (best < 0 || std::strcmp(g_commands[i].name, g_commands[best].name) < 0))
        best = i;
    }
    printed[best] = true;
    print(g_commands[best]);
  }
}

bool ParseNumber(const char* text, double min, double max, double* out) {
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(text, &end);
  if (end == text || *end != '\0' || errno != 0 || !std::isfinite(v) || v < min || v > max) {
    return false;
  }
  *out = v;
  return true;
}

bool ParseInteger(const char* text, long min, long max, long* out) {
  double v = 0;
  if (!ParseNumber(text, double(min), double(max), &v) || v != std::floor(v)) return false;
  *out = long(v);
  return true;
}

bool OptionNumber(const char* command, const char* option, const char* text, double min, double max,
                  double* out) {
  if (ParseNumber(text, min, max, out)) return true;
  std::fprintf(stderr, "stereohash %s: %s '%s' is not a number in %g..%g\n", command, option, text,
               min, max);
  return false;
}

bool OptionInteger(const char* command, const char* option, const char* text, long min, long max,
                   long* out) {
  if (ParseInteger(text, min, max, out)) return true;
  std::fprintf(stderr, "stereohash %s: %s '%s' is not a whole number in %ld..%ld\n", command,
               option, text, min, max);
  return false;
}

}  // namespace sh::tools
