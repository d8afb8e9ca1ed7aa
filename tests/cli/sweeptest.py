# SPDX-License-Identifier: MIT
"""What the sweep tests share: a failure that names its test, and a command that must exit as told."""
import subprocess
import sys


class Checker:
    def __init__(self, name):
        self.name = name

    def fail(self, msg):
        print("{}: FAIL: {}".format(self.name, msg), file=sys.stderr)
        sys.exit(1)

    def run(self, cmd, cwd, env=None, ok=(0,), note=None):
        """Runs cmd in cwd (env: the whole environment, or None for this one); fails unless it exits
        with one of `ok`, showing the ends of its outputs. `note` is named beside the command."""
        r = subprocess.run([str(c) for c in cmd], cwd=cwd, env=env, capture_output=True, text=True, timeout=600)
        if r.returncode not in ok:
            self.fail("{}{} exited with {}\nstdout:\n{}\nstderr:\n{}".format(
                " ".join(map(str, cmd)), " ({})".format(note) if note else "", r.returncode, r.stdout[-3000:],
                r.stderr[-3000:]))
        return r
