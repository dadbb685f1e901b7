#!/bin/sh
# Run under xvfb-run: start bims-viewer (args after the 2 files), wait until
# it wrote its own screenshot OWN, take an X screenshot XSHOT of the screen,
# stop the viewer. Usage: xshot.sh OWN XSHOT VIEWER [ARGS...]
own=$1
xshot=$2
shift 2
"$@" --screenshot "$own" --keep-open &
pid=$!
i=0
while [ ! -s "$own" ] && [ "$i" -lt 600 ]; do
	sleep 0.1
	i=$((i + 1))
done
sleep 1
import -window root "$xshot"
rc=$?
kill "$pid" 2>/dev/null
wait "$pid" 2>/dev/null
exit $rc
