#!/usr/bin/env bash
# Makes the screenshots of docs/console.md: `bowl monitor` on a virtual rig in a tmux terminal
# (120x36), captured with its colours, drawn as SVG (ansi_to_svg.py) and PNG (rsvg-convert,
# Debian package librsvg2-bin). Usage: bash docs/console/screenshots.sh
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
out=docs/console
cargo build -q -p host-tools
bowl=$PWD/target/debug/bowl
work=$(mktemp -d)
sock=bowl-screens-$$
cleanup() {
  tmux -L "$sock" kill-server 2>/dev/null || true
  [ -n "${serve_pid:-}" ] && kill "$serve_pid" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT
"$bowl" serve --pty --link "$work/rig" >"$work/serve.log" &
serve_pid=$!
sleep 1
tmux -L "$sock" new-session -d -x 120 -y 36 "$bowl monitor $work/rig; sleep 60"
keys() { tmux -L "$sock" send-keys -t 0 "$@"; }
shot() {
  tmux -L "$sock" capture-pane -e -p -t 0 >"$work/$1.ansi"
  python3 "$out/ansi_to_svg.py" "$work/$1.ansi" "$out/$1.svg"
  rsvg-convert "$out/$1.svg" -o "$out/$1.png"
  rm "$out/$1.svg"
  echo "$out/$1.png"
}
sleep 1
keys : "speed 1500 2100" Enter
keys : "start" Enter
sleep 8
keys : "status" Enter
sleep 1
shot running
keys : "inject sensor1" Enter
sleep 2
shot fault
kill "$serve_pid"
serve_pid=
sleep 1.5
shot link-lost
