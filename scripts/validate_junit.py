#!/usr/bin/env python3
"""Validates JUnit XML reports and reads them back as a CI system would.

    validate_junit.py SCHEMA.xsd REPORT.xml...

For each report: validates it against the XML Schema (xmlschema), checks
that every suite's and the root's tests/failures/errors/skipped counts are
those of the test cases they hold, then reads it with junitparser (the
parser several CI tools and GitHub actions use) and prints what it read as
one JSON line: the root's counts and, per suite, its counts, properties and
test cases (name, classname, result, message).

Exit status: 0 every report is valid, 1 a report is invalid (the reason on
stderr), 2 bad usage or a package is missing (pip install
xmlschema==4.3.2 junitparser==5.0.3).
"""

import json
import sys


def counts_of(cases):
    """tests/failures/errors/skipped of a list of <testcase> elements."""
    counts = {"tests": 0, "failures": 0, "errors": 0, "skipped": 0}
    for case in cases:
        counts["tests"] += 1
        tags = {child.tag for child in case}
        if "failure" in tags:
            counts["failures"] += 1
        elif "error" in tags:
            counts["errors"] += 1
        elif "skipped" in tags:
            counts["skipped"] += 1
    return counts


def check_counts(root):
    """Problems with the declared counts of the suites and the root."""
    problems = []
    total = {"tests": 0, "failures": 0, "errors": 0, "skipped": 0}
    for suite in root.iter("testsuite"):
        counted = counts_of(suite.findall("testcase"))
        for key, value in counted.items():
            total[key] += value
            declared = int(suite.get(key, "0"))
            if declared != value:
                problems.append(
                    f"testsuite {suite.get('name')!r}: {key}={declared}, but it holds {value}"
                )
    if root.tag == "testsuites":
        for key, value in total.items():
            declared = int(root.get(key, "0"))
            if declared != value:
                problems.append(f"testsuites: {key}={declared}, but the suites hold {value}")
    return problems


def read_back(path, junitparser):
    """What junitparser reads of the report."""
    xml = junitparser.JUnitXml.fromfile(path)
    suites = [xml] if isinstance(xml, junitparser.TestSuite) else list(xml)
    out = {
        "tests": xml.tests,
        "failures": xml.failures,
        "errors": xml.errors,
        "skipped": xml.skipped,
        "suites": [],
    }
    for suite in suites:
        cases = []
        for case in suite:
            result = "passed"
            message = None
            for r in case.result:
                if isinstance(r, junitparser.Failure):
                    result = "failure"
                elif isinstance(r, junitparser.Error):
                    result = "error"
                elif isinstance(r, junitparser.Skipped):
                    result = "skipped"
                message = r.message
            cases.append(
                {
                    "name": case.name,
                    "classname": case.classname,
                    "result": result,
                    "message": message,
                    "time": case.time,
                }
            )
        out["suites"].append(
            {
                "name": suite.name,
                "tests": suite.tests,
                "failures": suite.failures,
                "errors": suite.errors,
                "skipped": suite.skipped,
                "time": suite.time,
                "properties": {p.name: p.value for p in suite.properties()},
                "cases": cases,
            }
        )
    return out


def main(argv):
    if len(argv) < 3:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    try:
        import junitparser
        import xmlschema
    except ImportError as e:
        print(f"error: {e} (pip install xmlschema==4.3.2 junitparser==5.0.3)", file=sys.stderr)
        return 2
    schema = xmlschema.XMLSchema(argv[1])
    invalid = False
    for path in argv[2:]:
        errors = [f"{e.reason} at {e.path}" for e in schema.iter_errors(path)]
        if not errors:
            import xml.etree.ElementTree as ET

            errors = check_counts(ET.parse(path).getroot())
        if errors:
            invalid = True
            for e in errors:
                print(f"{path}: invalid: {e}", file=sys.stderr)
            continue
        print(json.dumps({"file": path, **read_back(path, junitparser)}))
    return 1 if invalid else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
