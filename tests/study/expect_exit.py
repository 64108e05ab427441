#!/usr/bin/python3
"""Runs a command and checks its exit code and that its standard error matches a pattern:
    expect_exit.py CODE PATTERN -- COMMAND...
ctest's PASS_REGULAR_EXPRESSION alone ignores the exit code, which the tools promise."""
import re
import subprocess
import sys


def main() -> int:
    if len(sys.argv) < 5 or sys.argv[3] != "--":
        print(__doc__, file=sys.stderr)
        return 2
    code, pattern, command = int(sys.argv[1]), sys.argv[2], sys.argv[4:]
    done = subprocess.run(command, capture_output=True, text=True, timeout=300)
    ok = True
    if done.returncode != code:
        print(f"exit code {done.returncode}, expected {code}", file=sys.stderr)
        ok = False
    if not re.search(pattern, done.stderr):
        print(f"standard error does not match {pattern!r}:\n{done.stderr}", file=sys.stderr)
        ok = False
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
