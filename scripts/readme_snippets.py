"""Runs every ```python block of README.md (run by scripts/test-all.sh), in order and in one
namespace, from the repository root, as a reader pasting them one after the other would. A
block that fails names its line in README.md."""

import pathlib
import re
import sys
import traceback

repo = pathlib.Path(__file__).resolve().parents[1]
text = (repo / "README.md").read_text()
blocks = [
    (text.count("\n", 0, m.start()) + 2, m.group(1))
    for m in re.finditer(r"```python\n(.*?)```", text, flags=re.S)
]
namespace: dict = {"__name__": "__readme__"}
failed = 0
for line, code in blocks:
    try:
        exec(compile(code, f"README.md:{line}", "exec"), namespace)
    except Exception:  # report every failing block, then fail
        failed += 1
        print(f"README.md line {line}: the block failed", file=sys.stderr)
        traceback.print_exc()
print(f"README snippets: {len(blocks) - failed} of {len(blocks)} python blocks ran")
sys.exit(1 if failed else 0)
