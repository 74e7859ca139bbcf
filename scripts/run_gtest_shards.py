#!/usr/bin/env python3
"""Runs one GoogleTest binary as N shards in parallel and writes ONE JUnit XML.

The core unit tests are the longest part of `./tissue test` (docs/DESIGN.md section 14) and
run in one process one test at a time; on a machine with N cores, gtest's own sharding
(GTEST_TOTAL_SHARDS / GTEST_SHARD_INDEX) runs them N at a time. catkin's run_tests wants one
result file per test target, so the shards' XML files are merged into the one named by --xml.

usage: run_gtest_shards.py OUT.xml BINARY [gtest args...]   (TISSUE_TEST_SHARDS=N: N shards)
Positional only: catkin's run_tests.py, which runs this command, parses options itself.
Exit status: 0 when every shard passed, else 1. Each shard's output is printed after it ends,
shard by shard (never interleaved).
"""
import os
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET


def default_shards():
    env = os.environ.get("TISSUE_TEST_SHARDS") or os.environ.get("TISSUE_JOBS")
    if env and env.isdigit() and int(env) > 0:
        return int(env)
    return max(1, min(os.cpu_count() or 1, 4))


def merge(xml_files, out_path):
    """One <testsuites> with every shard's <testsuite>s; the suite and total counters summed."""
    merged = ET.Element("testsuites", name="AllTests")
    totals = {"tests": 0, "failures": 0, "disabled": 0, "errors": 0}
    time = 0.0
    suites = {}
    for path in xml_files:
        root = ET.parse(path).getroot()
        for key in totals:
            totals[key] += int(root.get(key, "0"))
        time = max(time, float(root.get("time", "0")))
        for suite in root.findall("testsuite"):
            name = suite.get("name")
            if name not in suites:  # one element per suite, its cases from every shard
                suites[name] = ET.SubElement(merged, "testsuite", dict(suite.attrib))
                suites[name].extend(list(suite))
                continue
            target = suites[name]
            target.extend(list(suite))
            for key in ("tests", "failures", "disabled", "errors", "skipped"):
                if key in suite.attrib:
                    target.set(key, str(int(target.get(key, "0")) + int(suite.get(key))))
            target.set("time", "%.3f" % (float(target.get("time", "0")) + float(suite.get("time", "0"))))
    for key, value in totals.items():
        merged.set(key, str(value))
    merged.set("time", "%.3f" % time)
    os.makedirs(os.path.dirname(os.path.abspath(out_path)), exist_ok=True)
    ET.ElementTree(merged).write(out_path, encoding="UTF-8", xml_declaration=True)


def main():
    # Plain sys.argv: the gtest arguments after BINARY are passed on untouched.
    if len(sys.argv) < 3 or sys.argv[1] in ("-h", "--help"):
        print(__doc__)
        return 2
    out_xml, binary, extra = sys.argv[1], sys.argv[2], sys.argv[3:]
    shards = default_shards()
    with tempfile.TemporaryDirectory(prefix="gtest_shards_") as tmp:
        procs = []
        for i in range(shards):
            env = dict(os.environ, GTEST_TOTAL_SHARDS=str(shards), GTEST_SHARD_INDEX=str(i))
            if shards > 1:  # the shards are the parallelism: no BLAS/OpenMP threads on top
                env.setdefault("OPENBLAS_NUM_THREADS", "1")
                env.setdefault("OMP_NUM_THREADS", "1")
            xml = os.path.join(tmp, "shard%d.xml" % i)
            log = open(os.path.join(tmp, "shard%d.log" % i), "w+")
            cmd = [binary, "--gtest_output=xml:" + xml] + extra
            procs.append((subprocess.Popen(cmd, env=env, stdout=log, stderr=subprocess.STDOUT), xml, log))
        rc = 0
        xmls = []
        for i, (proc, xml, log) in enumerate(procs):
            code = proc.wait()
            log.seek(0)
            sys.stdout.write("---- shard %d of %d (exit %d) ----\n" % (i + 1, shards, code))
            sys.stdout.write(log.read())
            sys.stdout.flush()
            log.close()
            if code != 0:
                rc = 1
            if os.path.exists(xml):
                xmls.append(xml)
            else:  # crashed before writing: catkin_test_results must see a failure
                rc = 1
                print("run_gtest_shards: shard %d wrote no result (exit %d)" % (i + 1, code))
        if xmls:
            merge(xmls, out_xml)
        if len(xmls) < shards:
            # A failed case for the missing shard(s), so the merged file cannot read as a pass.
            root = ET.parse(out_xml).getroot() if xmls else ET.Element("testsuites", name="AllTests")
            suite = ET.SubElement(root, "testsuite", name="run_gtest_shards", tests="1", failures="1")
            case = ET.SubElement(suite, "testcase", name="every_shard_wrote_its_result",
                                 classname="run_gtest_shards")
            ET.SubElement(case, "failure", message="%d of %d shards wrote no result (crash?)"
                          % (shards - len(xmls), shards))
            ET.ElementTree(root).write(out_xml, encoding="UTF-8", xml_declaration=True)
    return rc


if __name__ == "__main__":
    sys.exit(main())
