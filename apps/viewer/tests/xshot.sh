#!/bin/sh
# Run under xvfb-run: start bims-viewer (args after the 2 files), take an X
# screenshot XSHOT of the screen, stop the viewer.
# Usage: xshot.sh OWN XSHOT VIEWER [ARGS...]
#   OWN a file: the viewer writes its own screenshot there after its
#       --max-frames and stays open; the X screenshot follows it.
#   OWN "-":    the viewer plays on; the X screenshot is taken while it plays,
#       2 s after the screen first shows the window.
own=$1
xshot=$2
shift 2
if [ "$own" = "-" ]; then
	"$@" &
else
	"$@" --screenshot "$own" --keep-open &
fi
pid=$!
i=0
while [ "$own" != "-" ] && [ ! -s "$own" ] && [ "$i" -lt 600 ]; do
	sleep 0.1
	i=$((i + 1))
done
# The X server may show the window a little after the viewer rendered its
# own screenshot (slow under load): retry until the screen is not blank.
rc=1
j=0
while [ "$j" -lt 30 ]; do
	sleep 1
	import -window root "$xshot"
	rc=$?
	if [ "$rc" -eq 0 ]; then
		mean=$(convert "$xshot" -format '%[fx:int(1000*mean)]' info: 2>/dev/null || echo 0)
		[ "${mean:-0}" -gt 20 ] && break
	fi
	j=$((j + 1))
done
if [ "$own" = "-" ] && [ "$rc" -eq 0 ]; then
	sleep 2
	import -window root "$xshot"
	rc=$?
	# still playing: the viewer has not quit on its own
	kill -0 "$pid" 2>/dev/null || rc=3
fi
kill "$pid" 2>/dev/null
wait "$pid" 2>/dev/null
exit $rc
