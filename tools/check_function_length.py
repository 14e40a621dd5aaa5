#!/usr/bin/env python3
"""No function of the library (src/), the tool (tools/) or the bindings (python/src/) longer than
LIMIT lines (ctest: function_length): a long function is several jobs, and the tools and the
bindings only parse, call and print. A function is a definition that starts at column 0
(namespaces do not indent) and ends at the first '}' at column 0 after it; one written on one line
is one line.
Usage: check_function_length.py SOURCE_DIR [LIMIT]"""
import pathlib
import re
import sys

root = pathlib.Path(sys.argv[1])
limit = int(sys.argv[2]) if len(sys.argv) > 2 else 120
start = re.compile(r"^[A-Za-z_][\w:<>,*&\s]*[\w>*&]\s+[\w:~]+\(|^[\w:~]+\(|^(CLI|PYBIND11)")
problems = []
files = sorted([*(root / "src").glob("**/*.cpp"), *(root / "tools").glob("*.cpp"), *(root / "python" / "src").glob("*.cpp")])
for path in files:
    lines = path.read_text().splitlines()
    i = 0
    while i < len(lines):
        one_line = "{" in lines[i] and lines[i].rstrip().endswith("}")
        if start.match(lines[i]) and not lines[i].rstrip().endswith(";") and not one_line:
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
print(f"{len(files)} files: every function of src/, tools/ and python/src/ is at most {limit} lines")
