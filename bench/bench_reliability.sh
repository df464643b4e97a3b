#!/usr/bin/env bash
# Reliability benchmark (issue: never crash, never lose work). Writes docs/RELIABILITY.md:
#  S. sanitizers: scripts/sanitize.sh address (AddressSanitizer + UndefinedBehaviorSanitizer +
#     LeakSanitizer: every unit test and an integration set) and scripts/sanitize.sh thread
#     (ThreadSanitizer: the threaded runner's tests); tests run, passed, failed (a sanitizer report
#     fails its test), build and test time (section sanitizers);
#  F. fuzzing: scripts/fuzz.sh with RUNS=FUZZ_RUNS inputs per target (libFuzzer, clang, ASan +
#     UBSan), from the seed corpus in fuzz/corpus: inputs tried, seconds, crashes / hangs / leaks
#     (section fuzzing);
#  I. interruption: `detslam run` on a synthetic static sequence (INT_FRAMES frames, default dnn
#     segmenter), SIGINT or SIGTERM once 100 frames are done, TRIALS times per mode: exit status,
#     seconds from the signal to the exit, frames in the outputs, run.json "interrupted"; and a
#     second SIGINT right after the first (section interruption);
#  X. faults: bench/fault_cases.py damages a synthetic sequence (or the command line, or the disk)
#     one way per case and checks the behaviour decided for it (section faults);
#  K. soak: `detslam run --threaded` (default dnn segmenter) on a synthetic `loop` sequence of
#     SOAK_FRAMES frames with a person, under a watchdog (bench/soak_monitor.py: no frame finished
#     for 120 s = hung, stacks dumped) sampling resident memory and the atlas size
#     (docs/reliability_soak.svg); then two sequential runs of its first SOAK_SEQ_FRAMES frames
#     whose outputs must be byte-identical (section soak).
#  C. CI time: a clean clone of the committed HEAD with ../shared beside it runs .ci/run as CI does
#     (CI=true, no compiler cache): each stage's seconds, the total, the result (section ci).
# Usage: bench/bench_reliability.sh [path/to/detslam]
#   (env: PARTS="S F I X K" (C only when named), TRIALS=3, INT_FRAMES=400, FUZZ_RUNS=100000, SOAK_FRAMES=20000,
#    SOAK_SEQ_FRAMES=1000)
set -euo pipefail
# The synthetic sensor model this benchmark's published section was measured with (easy until it
# is re-run on the realistic generator, `detslam synth`'s default).
export realism="${REALISM:-easy}"
here="$(cd "$(dirname "$0")" && pwd)"
root="$(dirname "$here")"
bin="${1:-$root/build/bin/detslam}"
parts="${PARTS:-S F I X K}"
fuzz_runs="${FUZZ_RUNS:-100000}"
trials="${TRIALS:-3}"
int_frames="${INT_FRAMES:-400}"
soak_frames="${SOAK_FRAMES:-20000}"
soak_seq_frames="${SOAK_SEQ_FRAMES:-1000}"
settings_line="bench/bench_reliability.sh (PARTS=\"$parts\" TRIALS=$trials INT_FRAMES=$int_frames FUZZ_RUNS=$fuzz_runs SOAK_FRAMES=$soak_frames SOAK_SEQ_FRAMES=$soak_seq_frames REALISM=$realism)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
bench_name=bench_reliability
# shellcheck source=bench/bench_lib.sh
source "$here/bench_lib.sh"
publish_doc() {  # section file
  python3 "$here/update_section.py" "$1" "$settings_line" RELIABILITY <"$2"
  cat "$2"
}

if want S; then
  out="$work/sanitizers.md"
  {
    echo "Each sanitizer build compiles every library, the \`detslam\` command and the tests with"
    echo "\`-fsanitize=...\` at -O2 (scripts/sanitize.sh, unity build); a report aborts its test, so a clean run is"
    echo "every selected test passing. Suppressions (scripts/sanitizers/*.supp) name system libraries"
    echo "only. Left uninstrumented, for speed: the synthetic generator under ThreadSanitizer (it runs"
    echo "on one thread there) and, with clang only, UBSan in the generator's renderer.cc (it keeps"
    echo "AddressSanitizer)."
    echo
    echo "| build | tests selected | passed | failed | build s | tests s |"
    echo "|---|---|---:|---:|---:|---:|"
  } >"$out"
  for kind in address thread; do
    progress "S: scripts/sanitize.sh $kind"
    log="$work/sanitize_$kind.log"
    set +e
    UNITY=1 "$root/scripts/sanitize.sh" "$kind" >"$log" 2>&1
    set -e
    python3 - "$log" "$kind" >>"$out" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
kind = sys.argv[2]
runs = re.findall(r"(\d+)% tests passed, (\d+) tests failed out of (\d+)", text)
total = sum(int(r[2]) for r in runs)
failed = sum(int(r[1]) for r in runs)
build = re.search(r"\[sanitize\] \w+ build: (\d+) s", text)
tests = re.findall(r"\[sanitize\] \w+ tests?: (\d+) s", text)
name = {"address": "AddressSanitizer + UndefinedBehaviorSanitizer + LeakSanitizer",
        "thread": "ThreadSanitizer"}[kind]
selected = {"address": "all unit tests; integration: runner, faults, map file, report, "
                       "vocabulary command; fr2/desk determinism",
            "thread": "bounded queue, stage threads; integration: runner, interruption (not the "
                      "second signal: its _exit with threads running is a thread leak by design); "
                      "fr2/desk threaded and mapping-thread runs"}[kind]
fails = re.findall(r"^\s*\d+ - (\S+) \(", text, re.M)
print(f"| {name} | {selected} | {total - failed} | {failed}"
      f"{' (' + ', '.join(fails) + ')' if fails else ''} | {build.group(1) if build else '?'} | "
      f"{sum(int(t) for t in tests) if tests else '?'} |")
PY
  done
  echo >>"$out"
  publish_doc sanitizers "$out"
fi

if want F; then
  progress "F: scripts/fuzz.sh, $fuzz_runs inputs per target"
  set +e
  RUNS="$fuzz_runs" "$root/scripts/fuzz.sh" >"$work/fuzz.log" 2>&1
  set -e
  out="$work/fuzzing.md"
  {
    echo "libFuzzer targets (fuzz/*_fuzz.cc; clang, AddressSanitizer + UndefinedBehaviorSanitizer +"
    echo "LeakSanitizer), each from its seed corpus (fuzz/corpus) for $fuzz_runs inputs; an input over"
    echo "10 s counts as a hang. A parser may refuse an input only with InputError: any other"
    echo "exception, a failed CHECK, a sanitizer report or a leak is a crash."
    echo
    echo "| target | what it reads | inputs tried | seconds | crashes, hangs, leaks |"
    echo "|---|---|---:|---:|---|"
    python3 - "$work/fuzz.log" <<'PY'
import re, sys
what = {
    "trajectory": "TUM trajectory / ground truth, then `detslam eval` on it (ATE, RPE)",
    "dataset": "rgb.txt, depth.txt, groundtruth.txt, association file (RgbdDataset::Open)",
    "mask_list": "a mask folder's instances.txt",
    "run_log": "run.json as `detslam report` reads it",
    "vocabulary": "vocabulary files (raw, or with a valid checksum), then words of descriptors",
    "map_file": "map files (raw, or with a valid checksum), loaded with their own header's camera",
    "settings": "settings YAML (both key styles) and --set values, resolved against every key",
    "rosbag": "ROS 1 bags (RosbagFile, RosbagSource: chunks, records, Image/CameraInfo/TFMessage)",
}
for line in open(sys.argv[1]):
    m = re.match(r"\[fuzz\] (\w+): (\S+) inputs in (\S+) s, no crash", line)
    if m:
        print(f"| {m.group(1)} | {what.get(m.group(1), '')} | {m.group(2)} | {m.group(3)} | 0 |")
        continue
    m = re.match(r"\[fuzz\] (\w+): FAILED \(exit (\d+)\) after (\S+) inputs", line)
    if m:
        print(f"| {m.group(1)} | {what.get(m.group(1), '')} | {m.group(3)} | - | FAILED (exit {m.group(2)}) |")
PY
    echo
  } >"$out"
  publish_doc fuzzing "$out"
fi

if want I; then
  progress "I: interruption ($int_frames-frame static sequence)"
  "$bin" synth --realism "$realism" --preset static --seed 1 --frames "$int_frames" --out "$work/seq" >/dev/null 2>&1
  : >"$work/int.tsv"
  interrupt_once() {  # mode signal twice trial
    local mode=$1 sig=$2 twice=$3 o="$work/int_$1_$2_$3_$4"
    local args=(run --dataset "$work/seq" --out "$o")
    [ "$mode" = threaded ] && args+=(--threaded)
    "$bin" "${args[@]}" >"$o.log" 2>&1 &
    local pid=$!
    until grep -q "\[run\] 100/" "$o.log" 2>/dev/null; do
      kill -0 "$pid" 2>/dev/null || { cat "$o.log"; exit 1; }
      sleep 0.01
    done
    local t0 t1 rc
    t0=$(date +%s.%N)
    kill "-$sig" "$pid"
    if [ "$twice" = yes ]; then
      until grep -q "again to quit at once" "$o.log"; do sleep 0.001; done
      kill -INT "$pid" 2>/dev/null || true
    fi
    set +e
    wait "$pid"
    rc=$?
    set -e
    t1=$(date +%s.%N)
    python3 - "$o" "$mode" "$sig" "$twice" "$rc" "$t0" "$t1" >>"$work/int.tsv" <<'PY'
import json, os, sys
o, mode, sig, twice, rc, t0, t1 = sys.argv[1:]
frames, interrupted, lines, tracked = "-", "-", "-", "-"
if os.path.exists(os.path.join(o, "run.json")):
    j = json.load(open(os.path.join(o, "run.json")))
    frames, interrupted = str(j["frames"]), str(j["interrupted"]).lower()
    tracked = str(j["frames_tracked"])
t = os.path.join(o, "trajectory.txt")
if os.path.exists(t):
    lines = str(sum(1 for l in open(t) if l.strip() and not l.startswith("#")))
print("\t".join([mode, sig, twice, rc, f"{float(t1) - float(t0):.3f}", frames, interrupted,
                 f"{lines}/{tracked}"]))
PY
  }
  for mode in sequential threaded; do
    for sig in INT TERM; do
      for t in $(seq "$trials"); do interrupt_once "$mode" "$sig" no "$t"; done
    done
    for t in $(seq "$trials"); do interrupt_once "$mode" INT yes "$t"; done
  done
  out="$work/interruption.md"
  {
    echo "\`detslam run\` (default dnn segmenter) on a synthetic \`static\` sequence of $int_frames frames,"
    echo "signalled once the progress line says 100 frames are done; $trials trials per row. Target:"
    echo "stops within a second with the outputs of the frames processed so far, marked interrupted;"
    echo "a second signal quits at once, leaving no truncated file."
    echo
    echo "| mode | signal | exit status | seconds from signal to exit: median | max | frames in run.json | run.json interrupted | trajectory.txt lines / tracked frames |"
    echo "|---|---|---|---:|---:|---|---|---|"
    python3 - "$work/int.tsv" <<'PY'
import statistics as st, sys
rows = [l.rstrip("\n").split("\t") for l in open(sys.argv[1]) if l.strip()]
for key in dict.fromkeys((r[0], r[1], r[2]) for r in rows):
    r = [x for x in rows if (x[0], x[1], x[2]) == key]
    secs = [float(x[4]) for x in r]
    sig = f"SIG{key[1]}" + (", then SIGINT" if key[2] == "yes" else "")
    print(f"| {key[0]} | {sig} | {', '.join(sorted(set(x[3] for x in r)))} | {st.median(secs):.2f} | "
          f"{max(secs):.2f} | {', '.join(x[5] for x in r)} | {', '.join(sorted(set(x[6] for x in r)))} | "
          f"{', '.join(x[7] for x in r)} |")
PY
    echo
  } >"$out"
  publish_doc interruption "$out"
fi

if want X; then
  progress "X: fault cases (bench/fault_cases.py)"
  out="$work/faults.md"
  set +e
  python3 "$here/fault_cases.py" "$bin" "$work/faults" >"$out"
  rc=$?
  set -e
  publish_doc faults "$out"
  [ "$rc" -eq 0 ] || { echo "bench_reliability: a fault case did not behave as decided" >&2; exit 1; }
fi

if want K; then
  progress "K: soak, $soak_frames frames (one synthetic lap of 960 frames, listed again and again)"
  seq="$work/soak_seq"
  "$bin" synth --realism "$realism" --preset loop --seed 1 --frames 960 --out "$seq" >/dev/null
  python3 "$here/repeat_sequence.py" "$seq" 32.0 "$soak_frames"
  progress "K: soak run (threaded, watchdog 120 s)"
  set +e
  python3 "$here/soak_monitor.py" "$work/soak" 120 -- "$bin" run --dataset "$seq" \
    --out "$work/soak_run" --threaded
  soak_rc=$?
  set -e
  ate="-"
  if [ -f "$work/soak_run/trajectory.txt" ]; then
    ate=$("$bin" eval --gt "$seq/groundtruth.txt" --est "$work/soak_run/trajectory.txt" \
      --json "$work/soak_eval.json" >/dev/null 2>&1 &&
      python3 "$here/cross_check_eval.py" "$work/soak_eval.json" &&
      python3 -c "import json,sys; print(f\"{json.load(open(sys.argv[1]))['ate']['rmse']:.4f}\")" \
        "$work/soak_eval.json" || echo "-")
  fi
  progress "K: two sequential runs of the first $soak_seq_frames frames"
  for k in 1 2; do
    "$bin" run --dataset "$seq" --out "$work/seq_run$k" --max-frames "$soak_seq_frames" \
      --no-progress >"$work/seq_run$k.log" 2>&1
  done
  identical=yes
  differing=""
  for f in $(cd "$work/seq_run1" && ls); do
    [ "$f" = run.json ] || [ "$f" = report.html ] && continue  # they hold timings
    cmp -s "$work/seq_run1/$f" "$work/seq_run2/$f" || { identical=NO; differing+=" $f"; }
  done
  files=$(cd "$work/seq_run1" && ls | grep -v -e '^run.json$' -e '^report.html$' | tr '\n' ' ')
  out="$work/soak.md"
  {
    echo "\`detslam run --threaded\` (default dnn segmenter) on $soak_frames frames at 30 Hz"
    echo "($((soak_frames / 1800)) min $(((soak_frames % 1800) / 30)) s): one lap of the synthetic \`loop\` preset (seed 1, 960"
    echo "frames = 32 s, the camera's circuit closes exactly; a person walks behind the desk) listed"
    echo "again and again with later timestamps (bench/repeat_sequence.py), so the camera goes round"
    echo "the same room $(( (soak_frames + 959) / 960 )) times; the images of each lap are the same files (the person"
    echo "jumps where a lap starts again). A run counts as hung when no frame finishes for 120 s"
    echo "(watchdog); memory is sampled twice a second."
    echo
    python3 "$here/soak_report.py" "$work/soak" "$work/soak_run" "$ate" "$soak_rc" "$soak_frames"
    echo "Repeated sequential runs (first $soak_seq_frames frames, same seed): outputs ${files}"
    echo "byte-identical: **$identical**${differing:+ (differ:$differing)}."
    echo
  } >"$out"
  publish_doc soak "$out"
  [ "$soak_rc" -eq 0 ] && [ "$identical" = yes ] ||
    { echo "bench_reliability: the soak run failed" >&2; exit 1; }
fi

if want C; then
  progress "C: .ci/run on a clean clone of HEAD ($(git -C "$root" rev-parse --short HEAD))"
  [ -z "$(git -C "$root" status --porcelain)" ] ||
    progress "C: the working tree has uncommitted changes; the clone has only what is committed"
  shared="$(cd "$root/../shared" 2>/dev/null && pwd)" ||
    { echo "bench_reliability: part C needs ../shared beside the repository" >&2; exit 1; }
  mkdir -p "$work/ci"
  git clone -q "$root" "$work/ci/repo"
  ln -sfn "$shared" "$work/ci/shared"
  start=$(date +%s)
  set +e
  (cd "$work/ci/repo" && unset CMAKE_CXX_COMPILER_LAUNCHER &&
    CI=true CCACHE_DISABLE=1 bash .ci/run) >"$work/ci.log" 2>&1
  ci_rc=$?
  set -e
  total=$(( $(date +%s) - start ))
  out="$work/ci.md"
  {
    echo "\`.ci/run\` on a clean clone of commit $(git -C "$root" rev-parse --short HEAD) with ../shared beside it, as CI"
    echo "runs it (CI=true, no compiler cache, Debian packages already installed). Seconds per stage"
    echo "(each stage builds its own folder from scratch, then runs its tests):"
    echo
    python3 - "$work/ci.log" "$total" "$ci_rc" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
total, rc = int(sys.argv[2]), int(sys.argv[3])
stages = re.findall(r"^\[ci\] (.+) \((\d+) s since the start\)$", text, re.M)
print("| stage | seconds |")
print("|---|---:|")
for (name, t0), (_, t1) in zip(stages, stages[1:]):
    print(f"| {name} | {int(t1) - int(t0)} |")
print(f"| **whole .ci/run** (with its package checks) | **{total}** ({total / 60:.1f} min) |")
print()
print(f"Result: {'passed' if rc == 0 else f'FAILED (exit status {rc})'}.")
PY
    echo
  } >"$out"
  publish_doc ci "$out"
  [ "$ci_rc" -eq 0 ] || { tail -50 "$work/ci.log" >&2; echo "bench_reliability: .ci/run failed" >&2; exit 1; }
fi
