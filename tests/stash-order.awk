# Reads strace -f -y -e trace=fsync,rename,renameat,renameat2 output of a run
# that replaces one: the stash's marker may change from .moving to .moved
# only after the directory and the stash were synced following the last
# file moved into it, and the stash is synced after it (a marker on disk
# must never say more than the moves before it); and before the first file
# moves, the stash (holding its marker) is synced, then the directory (a
# stash without a marker on disk is not linewise's).  At least 3 files moved
# (tests/test_cli.c).
{ line[NR] = $0; pid[NR] = $1 }
END {
  moved = 0; marker = 0
  for (i = 1; i <= NR; i++) {
    if (line[i] !~ / rename(at2?)?\(/) continue
    if (line[i] !~ /\.replaced\/\.moving", ".*\.replaced\/\.moved"/) {
      if (line[i] ~ /", "[^"]*\.replaced\//) { moved++; last = i; if (!first) first = i }
      continue
    }
    marker = i
  }
  if (!marker || !moved) { print "no stash: " moved " files moved, marker at line " marker; exit 1 }
  # the run's directory: the marker's path less /.replaced/.moving
  split(line[marker], q, "\""); dir = q[2]; sub(/\/\.replaced\/\.moving$/, "", dir); sub(/.*\//, "", dir)
  dir_synced = stash_synced = 0
  for (j = last + 1; j < marker; j++) {
    if (pid[j] != pid[marker] || line[j] !~ /fsync\(/) continue
    if (index(line[j], "/" dir "/.replaced>)")) stash_synced = 1
    else if (index(line[j], "/" dir ">)")) dir_synced = 1
  }
  pre_stash = pre_dir = 0
  for (j = 1; j < first; j++) {
    if (pid[j] != pid[marker] || line[j] !~ /fsync\(/) continue
    if (index(line[j], "/" dir "/.replaced>)")) pre_stash = 1
    else if (pre_stash && index(line[j], "/" dir ">)")) pre_dir = 1
  }
  after = ""
  for (j = marker + 1; j <= NR && after == ""; j++) if (pid[j] == pid[marker]) after = line[j]
  bad = 0
  if (!dir_synced) { bad++; print "directory not synced before the marker: " line[marker] }
  if (!stash_synced) { bad++; print "stash not synced before the marker: " line[marker] }
  if (!pre_stash) { bad++; print "stash not synced before the first move: " line[first] }
  if (!pre_dir) { bad++; print "directory not synced after the stash, before the first move: " line[first] }
  if (!index(after, "fsync(") || !index(after, "/" dir "/.replaced>)")) {
    bad++
    print "stash not synced after the marker: " after
  }
  print moved " files moved"
  exit !(moved >= 3 && bad == 0)
}
