#!/usr/bin/env python3
"""The function size check: no function (lambdas included) in recog/, tables/, firmware/, hal/ or
tools/ is longer than 150 lines, from the line of its name to its closing brace. Finds the
functions with universal-ctags (Debian package universal-ctags; tools/ci/install-deps.sh
installs it) and prints each one over the limit as `path:line: name is N lines (limit 150)`.

  tools/check_function_size.py [ROOT]   check the tree at ROOT (default: this checkout); exit 1
                                        with one line per problem, 2 without universal-ctags
"""
import os
import subprocess
import sys

LIMIT = 150
DIRECTORIES = ("recog", "tables", "firmware", "hal", "tools")


def universal_ctags():
    """The ctags command, or None after saying why it cannot be used."""
    try:
        version = subprocess.run(["ctags", "--version"], capture_output=True, text=True,
                                 check=False).stdout
    except OSError:
        version = None
    if version is None:
        print("check_function_size: ctags not found; install universal-ctags (Debian package "
              "universal-ctags, see tools/ci/install-deps.sh)", file=sys.stderr)
        return None
    if "Universal Ctags" not in version:
        first = version.splitlines()[0] if version else "(no version)"
        print("check_function_size: this ctags is not universal-ctags (it says: %s); install "
              "the Debian package universal-ctags" % first, file=sys.stderr)
        return None
    return "ctags"


def readable_name(name, scope_kind, scope):
    """`Class::Function` for a member, `Function` otherwise, or `lambda in F` for ctags'
    anonymous names (__anon...) of lambdas."""
    parts = [p for p in scope.split("::") if p]
    if name.startswith("__anon"):
        named = [p for p in parts if not p.startswith("__anon")]
        return "lambda in " + (named[-1] if named else "an anonymous scope")
    if scope_kind in ("class", "struct") and parts and not parts[-1].startswith("__anon"):
        return parts[-1] + "::" + name
    return name


def functions(ctags, root):
    """(path, line, name, length) of every function definition in DIRECTORIES."""
    dirs = [d for d in DIRECTORIES if os.path.isdir(os.path.join(root, d))]
    out = subprocess.run(
        [ctags, "-R", "--languages=C++", "--kinds-C++=f", "--fields=+neZ", "--excmd=number",
         "-f", "-"] + dirs, cwd=root, capture_output=True, text=True, check=True).stdout
    for line in out.splitlines():
        # NAME, PATH, LINE;", KIND, then KEY:VALUE fields (line, end, scope:KIND:NAME, ...).
        cols = line.split("\t")
        fields = {}
        for col in cols[3:]:
            key, sep, value = col.partition(":")
            if sep:
                fields[key] = value
        if len(cols) < 3 or "line" not in fields or "end" not in fields:
            continue
        scope_kind, _, scope = fields.get("scope", "").partition(":")
        first, last = int(fields["line"]), int(fields["end"])
        yield (os.path.normpath(cols[1]), first, readable_name(cols[0], scope_kind, scope),
               last - first + 1)


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..")
    root = os.path.abspath(root)
    ctags = universal_ctags()
    if ctags is None:
        return 2
    problems = ["%s:%d: %s is %d lines (limit %d)" % (path, line, name, length, LIMIT)
                for path, line, name, length in sorted(functions(ctags, root)) if length > LIMIT]
    for p in problems:
        print(p)
    if problems:
        print("check_function_size: %d problem(s); split long functions into smaller ones "
              "(each with one job)" % len(problems), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
