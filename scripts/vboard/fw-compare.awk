# Stage "fw" of the virtual board: compares the firmware's epochs decoded in the VM with the
# host-only reference run, epoch by epoch keyed by the sample counter, each field within ONE
# quantisation step of its CAN signal. Runs under busybox awk in the VM and any POSIX awk.
#
#   awk -F, -v rate=HZ -f fw-compare.awk gfins.dbc ref.csv vm.csv
#
# gfins.dbc is docs/can/gfins.dbc: each signal's step is its factor in
#   SG_ Name : start|len@1+ (factor,offset) [min|max] "unit" receivers
# and a CSV column of `gfins-can decode --view csv` is the signal's name, followed by
# "[unit]" when it has one (TimeUs[us], Roll[rad]).
#
# Why one step and not equality: the reference runs natively on the CI machine's CPU, the VM
# under QEMU TCG `-cpu max`; glibc's libm picks its sin/cos/atan2/exp/... variants by CPU
# feature (ifunc: FMA, AVX2), so a float32 result on a rounding boundary may quantise to the
# neighbouring step. Anything a plausible bug changes (a conversion taken from the wrong sample,
# a lost edge, another calibration) moves the values by many steps or drops an epoch.
# Tolerance per column:
#   - signals with a factor other than 1 (quantised physical values): |ref - vm| <= 1 step;
#     the fields that differ by exactly one step are counted;
#   - signals with factor 1 (counters, flags, modes, ids: their "one step" is another count,
#     flag or mode, never a rounding): equal;
#   - StatusFlags: equal except bit 15 "data-ready lost" and bit 13 "health degraded", which the
#     VM run sets, rightly, for the waits before the first edge (LAST_STARTUP says until when);
#   - node (the decoder's column, not a signal): equal; not compared: line, log_time_s and TimeUs
#     (the VM's log and clock);
#   - an empty field (message not carried by that epoch) must be empty in both.
# A column without a signal in the DBC, or a signal defined twice with different factors, is an
# error (ERR), as is a VM header different from the reference's.
#
# Prints one line:
#   MATCHED DIFFER MISSING ONE_STEP MAX_STEPS COMPARED FIRST LAST_STARTUP LIMIT ERR
# MATCHED/DIFFER: VM epochs within tolerance / not; MISSING: VM epochs without a reference epoch;
# ONE_STEP: fields exactly one step apart; MAX_STEPS: the largest difference in steps; COMPARED:
# fields compared; FIRST: the first out-of-tolerance field as Name@sample:ref/vm ("-" if none);
# LIMIT: 2 s of samples; ERR: "-" or what is wrong with the inputs.

# The largest difference in quantisation steps allowed for a quantised physical value (see above).
BEGIN { kMaxSteps = 1 }
# Decoded values print with 10 significant digits: a whole number of steps reads back within
# this fraction of a step.
BEGIN { kPrintSlack = 0.001 }

function masked(v) { return v - (int(v / 8192) % 2) * 8192 - (int(v / 32768) % 2) * 32768 }
function absv(x) { return x < 0 ? -x : x }
function problem(s) { gsub(/[ \t]/, "_", s); if (err == "") err = s }

FNR == 1 { ++file }

file == 1 {
  if ($0 !~ /^[ \t]*SG_[ \t]/) next
  s = $0
  sub(/^[ \t]*SG_[ \t]+/, "", s)
  nm = s
  sub(/[ \t:].*$/, "", nm)
  fo = s
  if (sub(/^[^(]*\(/, "", fo) != 1 || sub(/\).*$/, "", fo) != 1 || split(fo, p, ",") != 2) {
    problem("dbc-signal-" nm "-has-no-(factor,offset)")
    next
  }
  if ((nm in factor) && factor[nm] != p[1] + 0) conflict[nm] = 1
  factor[nm] = p[1] + 0
  next
}

file == 2 && FNR == 1 {
  header = $0
  n = NF
  for (i = 1; i <= NF; ++i) {
    name[i] = $i
    sig = $i
    sub(/\[.*$/, "", sig)
    if (sig == "SampleCount") key = i
    if ($i == "line" || $i == "log_time_s" || sig == "TimeUs") kind[i] = "skip"
    else if ($i == "node") kind[i] = "exact"
    else if (!(sig in factor)) { problem("column-" $i "-has-no-signal-in-the-dbc"); kind[i] = "exact" }
    else if (sig in conflict) { problem("signal-" sig "-has-two-factors-in-the-dbc"); kind[i] = "exact" }
    else if (sig == "StatusFlags") kind[i] = "flags"
    else if (factor[sig] == 1) kind[i] = "exact"
    else if (factor[sig] <= 0) { problem("signal-" sig "-has-factor-" factor[sig]); kind[i] = "exact" }
    else { kind[i] = "step"; step[i] = factor[sig] }
  }
  if (!key) problem("no-SampleCount-column-in-the-reference")
  next
}
file == 2 { ref[$key] = $0; next }

file == 3 && FNR == 1 { if ($0 != header) problem("the-VM-CSV-header-differs-from-the-reference's"); next }
file == 3 {
  if (!($key in ref)) { ++missing; if (!first) first = "epoch@" $key ":missing"; next }
  split(ref[$key], r, ",")
  bad = 0
  for (i = 1; i <= n; ++i) {
    k = kind[i]
    if (k == "skip") continue
    ++compared
    if (k == "flags") { same = masked(r[i]) == masked($i); if (r[i] != $i) last_startup = $key }
    else if (k == "exact" || r[i] == "" || $i == "") same = r[i] == $i
    else {
      d = absv(r[i] - $i) / step[i]
      steps = int(d + 0.5)
      same = d <= kMaxSteps + kPrintSlack
      if (steps > max_steps) max_steps = steps
      if (same && steps == 1) ++one_step
    }
    if (!same) { bad = 1; if (!first) first = name[i] "@" $key ":" r[i] "/" $i }
  }
  matched += !bad
  mism += bad
}

END {
  if (file < 3) problem("expected-3-files-(dbc,reference,VM)-got-" file + 0)
  print matched + 0, mism + 0, missing + 0, one_step + 0, max_steps + 0, compared + 0,
    (first ? first : "-"), last_startup + 0, 2 * rate, (err != "" ? err : "-")
}
