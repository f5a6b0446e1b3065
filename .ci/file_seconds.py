"""Write tests/file_seconds.txt, the seconds each test file took, from the JUnit XML of a full
run (``pytest -n 2 --dist loadfile --junitxml=run.xml``): ``python .ci/file_seconds.py run.xml``.
tests/conftest.py hands the files to the two xdist workers longest first by these figures, so
both end together; refresh it when files are added or get much slower or faster."""

import collections
import sys
import xml.etree.ElementTree as ET
from pathlib import Path


def main() -> None:
    seconds: collections.Counter = collections.Counter()
    for case in ET.parse(sys.argv[1]).iter("testcase"):
        module = case.get("classname", "").split(".")
        if len(module) >= 2 and module[0] == "tests":
            seconds[module[1] + ".py"] += float(case.get("time", 0.0))
    lines = ["# Seconds per test file in one full run (.ci/file_seconds.py from its JUnit XML): the order",
             "# in which tests/conftest.py hands the files to the xdist workers, longest first.",
             "# Only the order matters: a loaded machine scales them all alike."]
    lines += [f"{s:8.1f}  {name}" for name, s in seconds.most_common()]
    out = Path(__file__).resolve().parent.parent / "tests" / "file_seconds.txt"
    out.write_text("\n".join(lines) + "\n", encoding="utf-8")
    print(f"{out}: {len(seconds)} files, {sum(seconds.values()):.0f} s")


if __name__ == "__main__":
    main()
