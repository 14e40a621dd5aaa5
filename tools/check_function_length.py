#!/usr/bin/env python3
"""The tools and the bindings only parse, call and print: no function of tools/ or python/src/
longer than LIMIT lines (ctest: tool_functions). A function is a definition that starts at column
0 (namespaces do not indent) and ends at the first '}' at column 0 after it.
Usage: check_function_length.py SOURCE_DIR [LIMIT]"""
import pathlib
import re
import sys

root = pathlib.Path(sys.argv[1])
limit = int(sys.argv[2]) if len(sys.argv) > 2 else 120
start = re.compile(r"^[A-Za-z_][\w:<>,*&\s]*[\w>*&]\s+[\w:~]+\(|^[\w:~]+\(|^(CLI|PYBIND11)")
problems = []
files = sorted([*(root / "tools").glob("*.cpp"), *(root / "python" / "src").glob("*.cpp")])
for path in files:
    lines = path.read_text().splitlines()
    i = 0
    while i < len(lines):
        if start.match(lines[i]) and not lines[i].rstrip().endswith(";"):
            j = i
            while j < len(lines) and not (lines[j].startswith("}") and not lines[j].startswith("}  // namespace")):
                if j > i and start.match(lines[j]) and lines[j - 1].strip() == "":
                    break  # a declaration without a body before it
                j += 1
            if j < len(lines) and lines[j].startswith("}"):
                length = j - i + 1
                if length > limit:
                    name = lines[i].split("(")[0].split()[-1]
                    problems.append(f"{path.relative_to(root)}:{i + 1}: {name} is {length} lines (at most {limit}): split it")
                i = j
        i += 1
if problems:
    print("\n".join(problems))
    sys.exit(1)
print(f"{len(files)} files: every function of tools/ and python/src/ is at most {limit} lines")
