#!/usr/bin/env python3
"""The documents stay a map a newcomer can read: ARCHITECTURE.md at most 30 KB, no heading that
names an issue, every relative link in the project's Markdown resolving to a file or folder.
Example failure caught: a section appended per issue, or a README moved and its links left behind."""
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
LIMIT = 30 * 1024
failures = []

size = os.path.getsize(os.path.join(ROOT, "ARCHITECTURE.md"))
if size > LIMIT:
    failures.append(f"ARCHITECTURE.md is {size} bytes; the map stays within {LIMIT}: move detail beside its code")

try:
    listed = subprocess.run(["git", "-C", ROOT, "ls-files", "-co", "--exclude-standard", "*.md"],
                            capture_output=True, text=True, check=True).stdout.split()
except (OSError, subprocess.CalledProcessError):
    listed = [os.path.relpath(os.path.join(d, f), ROOT) for d, _, fs in os.walk(ROOT)
              for f in fs if f.endswith(".md") and "/build" not in d and "/." not in d]

heading = re.compile(r"^#{1,6}\s.*\b(issue|issues)\b\s*#?\d", re.IGNORECASE)
link = re.compile(r"\]\(([^)\s]+)\)")
for rel in listed:
    path = os.path.join(ROOT, rel)
    if not os.path.isfile(path):
        continue
    in_code = False
    with open(path, encoding="utf-8", errors="replace") as f:
        for number, line in enumerate(f, 1):
            if line.startswith("```"):
                in_code = not in_code
            if in_code:
                continue
            if heading.match(line):
                failures.append(f"{rel}:{number}: a heading names an issue: {line.strip()}")
            for target in link.findall(line):
                if re.match(r"^[a-z]+:", target) or target.startswith("#"):
                    continue
                file_part = target.split("#")[0]
                if not file_part:
                    continue
                resolved = os.path.normpath(os.path.join(os.path.dirname(path), file_part))
                if not os.path.exists(resolved):
                    failures.append(f"{rel}:{number}: the link '{target}' leads nowhere")

for f in failures:
    print("FAILED:", f)
print(f"{1 if not failures else 0} passed, {1 if failures else 0} failed ({len(failures)} problem(s))")
sys.exit(1 if failures else 0)
