# Reads strace -f -y -e trace=fsync,rename,renameat,renameat2 output: every
# rename of a run's file must follow the fsync of its temporary file and be
# followed by the fsync of its directory, in the same process (exit 0), and
# there must be at least 5 renames (tests/test_cli.c).  A state.lw counts the
# trace's bytes, so the trace is synced before each state.lw's rename (since
# the one before): a power cut left a state that counted rows the trace lost.
{ line[NR] = $0; pid[NR] = $1 }
/ fsync\(.*\/trace\.csv>\)/ { trace_synced[$1] = 1 }
/ rename(at2?)?\(.*state\.lw\.tmp", ".*\/state\.lw"/ {
  if (!trace_synced[$1]) { bad_trace++; print "trace not synced before: " $0 }
  trace_synced[$1] = 0
}
END {
  bad = 0; n = 0
  for (i = 1; i <= NR; i++) {
    if (line[i] !~ / rename(at2?)?\(/) continue
    n++
    split(line[i], q, "\""); tmp = q[2]; dst = q[4]; dir = dst; sub(/\/[^\/]*$/, "", dir)
    before = after = ""
    for (j = i - 1; j > 0 && before == ""; j--) if (pid[j] == pid[i]) before = line[j]
    for (j = i + 1; j <= NR && after == ""; j++) if (pid[j] == pid[i]) after = line[j]
    if (index(before, "fsync(") == 0 || index(before, tmp ">)") == 0) { bad++; print "not synced before: " line[i] }
    if (index(after, "fsync(") == 0 || index(after, "/" dir ">)") == 0) {
      bad++
      print "directory not synced after: " line[i]
    }
  }
  print n " renames"
  exit !(n >= 5 && bad == 0 && bad_trace == 0)
}
