# Reads strace -f -y -e trace=fsync,rename,renameat,renameat2 output: every
# rename of a run's file must follow the fsync of its temporary file and be
# followed by the fsync of its directory, in the same process (exit 0), and
# there must be at least 5 renames (tests/test_cli.c).
{ line[NR] = $0; pid[NR] = $1 }
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
  exit !(n >= 5 && bad == 0)
}
