#!/usr/bin/env bash
# Poll for job_next.sh (issue 9): the job log, the run's last progress line, and a copy of the run folder into $OUT
# on every call, so a machine taken back at its 30-minute hold loses at most the episodes in flight.
# Usage (device call, back to back with a sleep): sleep 240; bash ~/src/poll_next.sh
cat ~/chunks/job.log 2>/dev/null
grep -h "episodes done\|time box" ~/chunks/g1_eval/table_td_dry_sand.log 2>/dev/null | tail -1
[ -d ~/chunks/g1_eval/table_td_dry_sand ] && tar czf "$OUT/table_td_dry_sand.tgz" --exclude='*.png' -C ~/chunks/g1_eval table_td_dry_sand
ls ~/chunks/FG_DONE 2>/dev/null
