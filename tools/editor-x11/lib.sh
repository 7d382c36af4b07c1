# Shared by the editor's X11 scripts (sourced): installing Xvfb and xdotool, starting an X
# server on a free display, starting the editor on it and waiting for its window.
#
# Expects: $root (the checkout), $sinew (the binary). Defines skip, fail, make_work (a scratch
# folder $work, removed with the editor and X server at exit), need_x11 (installs or skips),
# start_x11 (sets DISPLAY, xvfb_pid) and start_editor
# ARGS… (sets editor_pid, wid, and the window geometry X, Y, WIDTH, HEIGHT; `at DX DY` prints
# a screen point relative to the window).

make_work() {
  work="$(mktemp -d)"
  xvfb_pid=""; editor_pid=""
  trap cleanup EXIT
}

cleanup() {
  [ -n "$editor_pid" ] && kill "$editor_pid" 2>/dev/null || true
  [ -n "$xvfb_pid" ] && kill "$xvfb_pid" 2>/dev/null || true
  rm -rf "$work"
}

skip() { echo "editor-x11: skipped: $*"; exit 0; }
fail() { echo "editor-x11: FAILED: $*" >&2; exit 1; }

need_x11() {
  need=()
  command -v Xvfb >/dev/null || need+=(xvfb xauth)
  command -v xdotool >/dev/null || need+=(xdotool)
  command -v python3 >/dev/null || need+=(python3)
  if [ "${#need[@]}" -gt 0 ]; then
    command -v apt-get >/dev/null || skip "no apt-get to install ${need[*]}"
    if [ "$(id -u)" -eq 0 ]; then as_root=(); elif command -v sudo >/dev/null && sudo -n true 2>/dev/null; then as_root=(sudo -n); else skip "need root or sudo to install ${need[*]}"; fi
    "${as_root[@]}" apt-get update -qq >/dev/null 2>&1 || skip "apt-get update failed (offline?)"
    "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
      "${need[@]}" libgl1-mesa-dri libegl1 libxkbcommon-x11-0 libxcursor1 libxrandr2 libxi6 \
      >/dev/null 2>&1 || skip "could not install ${need[*]}"
  fi
}

start_x11() {
  # A free display number, our own X server.
  display=""
  for n in $(seq 90 140); do
    [ -e "/tmp/.X11-unix/X$n" ] || [ -e "/tmp/.X$n-lock" ] || { display=":$n"; break; }
  done
  [ -n "$display" ] || skip "no free X display number"
  Xvfb "$display" -screen 0 1280x800x24 -nolisten tcp >/dev/null 2>&1 &
  xvfb_pid=$!
  export DISPLAY="$display"
  for _ in $(seq 50); do xdotool getmouselocation >/dev/null 2>&1 && break; sleep 0.1; done
  xdotool getmouselocation >/dev/null 2>&1 || skip "Xvfb did not start"
}

start_editor() {
  LIBGL_ALWAYS_SOFTWARE=1 "$sinew" edit "$@" >"$work/editor.log" 2>&1 &
  editor_pid=$!
  wid=""
  for _ in $(seq 120); do
    wid="$(xdotool search --name '^sinew' 2>/dev/null | head -1)" && [ -n "$wid" ] && break
    kill -0 "$editor_pid" 2>/dev/null || fail "the editor exited: $(cat "$work/editor.log")"
    sleep 0.25
  done
  [ -n "$wid" ] || fail "no editor window after 30 s"
  sleep 4 # first frames under software GL
  # No window manager: give the window the keyboard focus ourselves.
  xdotool windowfocus "$wid" 2>/dev/null || true
  eval "$(xdotool getwindowgeometry --shell "$wid")"
  at() { echo $((X + $1)) $((Y + $2)); }
}
