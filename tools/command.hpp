// Subcommands of the `stereohash` host program register themselves here, one file each.
#pragma once

namespace sh::tools {

struct Command {
  const char* name;     // e.g. "render"; "tables build" style groups use their first word
  const char* summary;  // one line for `stereohash --help`
  int (*run)(int argc, char** argv);  // argv[0] is the command name; returns the exit code
};

void RegisterCommand(const Command& command);
const Command* FindCommand(const char* name);
void ListCommands(void (*print)(const Command&));

// One step of a `--option value` loop over argv[1..]: sets *option and *value and moves *i onto
// the value. Returns false when the command should end with *exit_code: 0 after `--help`/`-h`
// (help printed), 2 for an option without a value or given a second time (message naming
// `command` printed; only `--set` of the bench commands may be repeated).
bool NextOption(const char* command, int argc, char** argv, void (*print_help)(), int* i,
                const char** option, const char** value, int* exit_code);

// A finite number in [min, max] from the whole of `text` (no trailing characters); false
// otherwise, *out untouched.
bool ParseNumber(const char* text, double min, double max, double* out);
// The same for a whole number ("5x", "2.5" and "" are refused).
bool ParseInteger(const char* text, long min, long max, long* out);
// ParseNumber / ParseInteger of an option's value; false after printing "stereohash COMMAND:
// OPTION 'VALUE' is not a number in MIN..MAX".
bool OptionNumber(const char* command, const char* option, const char* text, double min, double max,
                  double* out);
bool OptionInteger(const char* command, const char* option, const char* text, long min, long max,
                   long* out);

struct CommandRegistrar {
  explicit CommandRegistrar(const Command& command) { RegisterCommand(command); }
};

}  // namespace sh::tools

// Usage at namespace scope: SH_REGISTER_COMMAND(render, "draw a stereo pair", RunRender);
#define SH_REGISTER_COMMAND(id, summary, fn) \
  static ::sh::tools::CommandRegistrar sh_command_##id({#id, summary, fn})
