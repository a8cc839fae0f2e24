# Reads strace -f -y -e trace=fsync,rename,renameat,renameat2,unlink,unlinkat
# output of a run that failed before its first sweep and put back the run it
# replaced, having written a file the run before had not (a frame; see
# tests/test_dynamics_cli.c).  The marker may say .restoring only
# once the new run's files that have no counterpart are gone on disk (the
# run's directory synced after the last such removal), and is synced itself;
# the marker may go only once every file moved back is on disk (directory
# and stash synced after the last move back).  At least 3 files moved back.
{ line[NR] = $0; pid[NR] = $1 }
# whether process p synced path between lines from and to
function synced(from, to, p, path,   j) {
  for (j = from + 1; j < to; j++)
    if (pid[j] == p && line[j] ~ /fsync\(/ && index(line[j], path ">)")) return 1
  return 0
}
END {
  restoring = gone = removed = 0; back = 0; last_back = last_unlink = 0
  for (i = 1; i <= NR; i++) {
    if (line[i] ~ /\.replaced\/\.moved", "[^"]*\.replaced\/\.restoring"/) { restoring = i; continue }
    if (line[i] ~ /unlink(at)?\(.*\.replaced\/\.restoring"/) { gone = i; continue }
    if (line[i] ~ / rename(at2?)?\("[^"]*\.replaced\/[^."][^"]*", /) { back++; last_back = i; continue }
    # (a removal that took place: a .tmp not there fails with ENOENT)
    if (!restoring && line[i] ~ /unlink(at)?\(.*= 0$/ && line[i] !~ /\.replaced/) { removed++; last_unlink = i }
  }
  if (!restoring || !gone || back < 3 || !removed) {
    print "no put-back: marker " restoring ", gone " gone ", " back " moved back, " removed " of the new run's removed"
    exit 1
  }
  p = pid[restoring]
  for (after = restoring + 1; after <= NR && pid[after] != p; after++) {}
  split(line[restoring], q, "\""); dir = q[2]; sub(/\/\.replaced\/\.moved$/, "", dir); sub(/.*\//, "", dir)
  bad = 0
  if (!synced(last_unlink, restoring, p, "/" dir)) {
    bad++
    print "directory not synced before .restoring: " line[restoring]
  }
  if (!synced(restoring, after + 1, p, "/" dir "/.replaced")) { bad++; print "stash not synced after .restoring" }
  if (!synced(last_back, gone, p, "/" dir)) { bad++; print "directory not synced before the marker goes: " line[gone] }
  if (!synced(last_back, gone, p, "/" dir "/.replaced")) { bad++; print "stash not synced before the marker goes" }
  print back " files moved back"
  exit bad != 0
}
