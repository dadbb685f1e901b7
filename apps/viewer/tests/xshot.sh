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
# The X server may show the window a little after the viewer rendered its
# own screenshot (slow under load): retry until the screen is not blank.
rc=1
j=0
while [ "$j" -lt 10 ]; do
	sleep 1
	import -window root "$xshot"
	rc=$?
	if [ "$rc" -eq 0 ]; then
		mean=$(convert "$xshot" -format '%[fx:int(1000*mean)]' info: 2>/dev/null || echo 0)
		[ "${mean:-0}" -gt 20 ] && break
	fi
	j=$((j + 1))
done
kill "$pid" 2>/dev/null
wait "$pid" 2>/dev/null
exit $rc
