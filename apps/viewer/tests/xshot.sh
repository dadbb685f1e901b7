#!/bin/sh
# Run under xvfb-run: start bims-viewer (args after the 2 files), take X
# screenshots of the screen, stop the viewer.
# Usage: xshot.sh OWN XSHOT VIEWER [ARGS...]
#   OWN a file: the viewer writes its own screenshot there after its
#       --max-frames and stays open; the X screenshot follows it.
#   OWN "-":    the viewer plays on; the X screenshot is taken while it plays,
#       2 s after the screen first shows the window.
#   OWN "play2": XSHOT is a prefix; the viewer plays with --state-file
#       XSHOT.state.json; once it has drawn a frame, two X screenshots 3 s
#       apart, XSHOT.1.png and XSHOT.2.png, each with a copy of the state
#       file taken right after it (XSHOT.1.json, XSHOT.2.json).
# XSHOT_BUSY=1 keeps one CPU busy with another process meanwhile.
own=$1
xshot=$2
shift 2
busy=
if [ "${XSHOT_BUSY:-0}" = 1 ]; then
	sh -c 'while :; do :; done' &
	busy=$!
fi
finish() {
	kill "$pid" 2>/dev/null
	wait "$pid" 2>/dev/null
	[ -n "$busy" ] && kill "$busy" 2>/dev/null
	exit "$1"
}
if [ "$own" = "play2" ]; then
	state="$xshot.state.json"
	rm -f "$state" "$xshot.1.png" "$xshot.2.png" "$xshot.1.json" "$xshot.2.json"
	"$@" --state-file "$state" &
	pid=$!
	i=0
	# until the state file says a frame was drawn (it is written at open,
	# with frame -1: a large first frame may take seconds under load)
	drawn() { grep -q '"frame": *[0-9]' "$state" 2>/dev/null; }
	while ! drawn && [ "$i" -lt 1200 ]; do
		sleep 0.1
		i=$((i + 1))
	done
	drawn || finish 4
	sleep 1
	for k in 1 2; do
		import -window root "$xshot.$k.png" || finish 5
		cp "$state" "$xshot.$k.json"
		[ "$k" = 1 ] && sleep 3
	done
	kill -0 "$pid" 2>/dev/null || finish 3
	finish 0
fi
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
finish $rc
