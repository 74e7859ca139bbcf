#!/usr/bin/env bash
# The gl backend on a real GPU, in one run: the GL unit tests, the offline solver with both
# backends on the shipped scenes, and the GPU benchmarks (the paper's Table 2 and the CG scaling
# rows; docs/DESIGN.md section 9). Used on a lent NVIDIA machine (README, "The GPU backend on a
# real GPU"); works on any machine with EGL, llvmpipe included (slowly). On a machine without
# this project's libraries, copy the binaries' `ldd` libraries (not libc, libstdc++ or GL) into
# a folder on LD_LIBRARY_PATH, and give EGL a vendor library (libglvnd's libegl1 and the
# driver's egl_vendor.d JSON, e.g. __EGL_VENDOR_LIBRARY_FILENAMES).
#
#   scripts/gpu_check.sh BUILD_DIR OUT_DIR
#
# BUILD_DIR holds tissue_core_unit, tissue_solve and tissue_bench (a Release core-only build:
# cmake -DTISSUE_CORE_ONLY=ON). Everything lands in OUT_DIR; each part runs whatever the others
# did, and the script's status is that of the tests.
set -u
build=${1:?usage: gpu_check.sh BUILD_DIR OUT_DIR}
out=${2:?usage: gpu_check.sh BUILD_DIR OUT_DIR}
mkdir -p "$out"
here=$(cd "$(dirname "$0")/.." && pwd)

echo "== GPU"
(nvidia-smi -L || true) 2>&1 | tee "$out/gpu.txt"

echo "== GL unit tests"
# Leading '*': parameterized suites are named Instantiation/Suite.Test/N.
gl_tests='*GpuCg*:*GpuSpmv*:*GpuReduction*:*GpuFallback*:*GlRefinement*:*GlScenes*'
gl_tests+=':SimulationPipeline.GlBackend*:SolveCli.GlBackend*'
# The offline-solver tests run BUILD_DIR's tissue_solve, not the build tree's (absent there).
TISSUE_SOLVE_BIN="$build/tissue_solve" timeout 240 "$build/tissue_core_unit" --gtest_filter="$gl_tests" \
  --gtest_output="xml:$out/gl_tests.xml" 2>&1 | tee "$out/gl_tests.log" | grep -E '^\[ +(OK|FAILED|PASSED) |renderer|fell back'
tests_status=${PIPESTATUS[0]}

echo "== tissue solve, cpu and gl"
rm -f "$out/solves.jsonl" "$out/solves.log"
for scene in thigh_generated liver_cut liver_organ; do
  for backend in cpu gl; do
    TIMEFORMAT="$scene $backend: %R s wall"
    time timeout 120 "$build/tissue_solve" "$here/config/scenes/$scene.yaml" --backend "$backend" \
      --stats "$out/stats.json" > "$out/solve.log" 2>&1
    tail -2 "$out/solve.log"
    # Few files come back from a lent machine: one line of stats per run.
    { printf '{"scene": "%s", "stats": ' "$scene"; tr -d '\n' < "$out/stats.json"; echo '}'; } \
      >> "$out/solves.jsonl"
    cat "$out/solve.log" >> "$out/solves.log"
  done
done

rm -f "$out/stats.json" "$out/solve.log"
[ "${GPU_CHECK_BENCH:-1}" = 1 ] || exit "$tests_status"
echo "== GPU benchmarks"
timeout 300 "$build/tissue_bench" --benchmark_filter="${GPU_CHECK_BENCH_FILTER:-Table2|Scaling}" \
  --benchmark_repetitions=3 --benchmark_report_aggregates_only=true \
  --benchmark_out="$out/gpu_bench.json" --benchmark_out_format=json 2>&1 | grep -E 'median|gl_renderer' \
  | tee "$out/gpu_bench.txt"
exit "$tests_status"
