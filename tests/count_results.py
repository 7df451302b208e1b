#!/usr/bin/python3
"""Counts test cases in a catkin test_results tree: prints "N passed, N failed".

catkin_test_results counts gtest's <testsuites> and its <testsuite> children both, so it reports
twice the number of tests; this reads each file's top-level element only. Each failed case is named
with the first lines of its message, so that a CI log says what failed. Exits 1 on any failure or
when no test ran.
"""
import pathlib
import sys
import xml.etree.ElementTree as ElementTree

passed = failed = 0
for path in sorted(pathlib.Path(sys.argv[1]).rglob("*.xml")):
    try:
        root = ElementTree.parse(path).getroot()
    except ElementTree.ParseError:
        print(f"unreadable result file: {path}")
        failed += 1
        continue
    tests = int(root.get("tests", 0))
    bad = int(root.get("failures", 0)) + int(root.get("errors", 0))
    skipped = int(root.get("skipped", 0)) + int(root.get("disabled", 0))
    passed += tests - bad - skipped
    failed += bad
    if bad:
        print(f"{path.name}: {bad} failed")
        for case in root.iter("testcase"):
            for problem in case.findall("failure") + case.findall("error"):
                text = (problem.get("message") or "") + "\n" + (problem.text or "")
                lines = [line for line in text.strip().splitlines() if line.strip()][:12]
                print(f"  {case.get('classname', '')}.{case.get('name')}:")
                for line in lines:
                    print(f"    {line}")
if passed + failed == 0:
    failed = 1
    print("no test results found")
print(f"{passed} passed, {failed} failed")
sys.exit(1 if failed else 0)
