"""The README's C example must be examples/c/reconstruct_minimal.c, verbatim (that file is
built and run by the `c_example` test, so the README cannot show code that does not work)."""
import pathlib
import re
import sys

root = pathlib.Path(sys.argv[1])
readme = (root / "README.md").read_text()
section = re.search(r"<!-- c-example:begin -->(.*?)<!-- c-example:end -->", readme, re.S)
if not section:
    sys.exit("README.md has no c-example section")
block = re.search(r"```c\n(.*?)```", section.group(1), re.S)
source = (root / "examples/c/reconstruct_minimal.c").read_text()
if not block or block.group(1) != source:
    sys.exit("README.md's C example differs from examples/c/reconstruct_minimal.c")
print("1 passed, 0 failed")
