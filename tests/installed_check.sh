#!/usr/bin/env bash
# `vkray check` as a user runs it: installed by `cmake --install` into a fresh prefix and run from a
# folder outside the source and build trees, with the validation layer on. Every case must pass, and
# the JUnit report must be well-formed XML that an independent reader (Python's ElementTree) accepts,
# with one testcase per printed case and each case's scene taken from the installed tree.
# Usage: installed_check.sh BUILD_DIR CMAKE
set -euo pipefail
build=$1 cmake=$2
work=$(cd "$(mktemp -d)" && pwd -P)  # as /proc/self/exe will name it, with no symlink in the way
keep() { echo "installed_check: kept $work (the install, out.txt, report.xml, vkray-check-failures/)" >&2; }
trap 'status=$?; if [ $status -eq 0 ]; then rm -rf "$work"; else keep; fi' EXIT
"$cmake" --install "$build" --prefix "$work/prefix" > /dev/null
cd "$work"
status=0
"$work/prefix/bin/vkray" check --validate --junit report.xml > out.txt || status=$?
cat out.txt
if [ "$status" -ne 0 ]; then
  echo "installed_check: vkray check exited $status" >&2
  exit 1
fi
python3 - "$work/prefix" <<'PYTHON'
import sys
import xml.etree.ElementTree as ET

prefix = sys.argv[1]
suite = ET.parse("report.xml").getroot().find("testsuite")
cases = suite.findall("testcase")
printed = [line for line in open("out.txt") if line.startswith(("pass ", "FAIL "))]
problems = []
if len(cases) != len(printed) or len(cases) < 60:
    problems.append(f"{len(cases)} testcases in the JUnit file, {len(printed)} printed")
if suite.get("failures") != "0" or suite.get("errors") != "0":
    problems.append(f"failures {suite.get('failures')}, errors {suite.get('errors')}")
properties = {p.get("name"): p.get("value") for p in suite.find("properties")}
for key in ("vkray_version", "device", "driver", "vulkan_version"):
    if not properties.get(key):
        problems.append(f"property {key} missing")
for case in cases:
    out = case.find("system-out").text
    if f"parity {prefix}/share/vkray/" not in out:
        problems.append(f"{case.get('classname')}.{case.get('name')} is not from the installed tree: {out}")
if problems:
    sys.exit("installed_check: " + "\n  ".join(problems))
print(f"installed_check: {len(cases)} JUnit testcases, all passed, read back by Python's ElementTree")
PYTHON
