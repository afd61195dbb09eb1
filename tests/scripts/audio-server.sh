#!/usr/bin/env bash
# A real audio server for the tests, with no sound card: PulseAudio (Debian: apt-get install
# pulseaudio pulseaudio-utils libasound2-plugins) with one null sink, `timpanist_null`
# (48 kHz float stereo), as the default sink, and ALSA's default device routed to it, so
# the editor plays through kira → cpal → ALSA → PulseAudio and a test records what it played
# from the sink's monitor (`parec -d timpanist_null.monitor`). Works as root with no
# systemd user session or D-Bus (as CI runs): the server is a plain daemon on its own
# socket, found by clients through PULSE_SERVER.
#
#   eval "$(tests/scripts/audio-server.sh start)"   # start (idempotent); exports PULSE_SERVER
#   tests/scripts/audio-server.sh env                # print the environment only
#   tests/scripts/audio-server.sh status             # exit 0 if it answers
#   tests/scripts/audio-server.sh stop               # stop it and undo the ALSA routing
#   tests/scripts/audio-server.sh kill               # stop the server only (the device
#                                                    # "disappears"; `start` brings it back)
#
# Only the `export` lines go to standard output (messages go to standard error), so the
# output of `start` can be eval'ed. The folder is TIMPANIST_PULSE_DIR (default
# /tmp/timpanist-pulse-$UID): the socket `native`, the pid file, the log.
set -euo pipefail

dir=${TIMPANIST_PULSE_DIR:-/tmp/timpanist-pulse-$(id -u)}
socket="$dir/native"
sink=timpanist_null
# ALSA's default device → PulseAudio, written only where no ~/.asoundrc of the user's own
# is (one this script wrote carries the marker and is removed by `stop`). Debian's
# libasound2-plugins routes ALSA to a running PulseAudio by itself too (alsa.conf.d
# pulse.conf); the file makes it explicit, so a process that first read its ALSA
# configuration while the server was down still plays to it once it is back.
asoundrc="${HOME:-$(getent passwd "$(id -u)" | cut -d: -f6)}/.asoundrc"
marker="# written by timpanist tests/scripts/audio-server.sh"

say() { echo "audio-server: $*" >&2; }

pa() { PULSE_SERVER="unix:$socket" "$@"; }

answers() { pa pactl info >/dev/null 2>&1; }

print_env() {
    echo "export PULSE_SERVER=unix:$socket"
}

route_alsa() {
    if [ -e "$asoundrc" ] && ! grep -qF "$marker" "$asoundrc"; then
        say "$asoundrc exists and is not this script's: left alone (ALSA may not default to PulseAudio)"
        return
    fi
    printf '%s\npcm.!default { type pulse }\nctl.!default { type pulse }\n' "$marker" >"$asoundrc"
}

need() {
    for tool in pulseaudio pactl parec; do
        if ! command -v "$tool" >/dev/null; then
            say "$tool not found: apt-get install pulseaudio pulseaudio-utils libasound2-plugins"
            exit 1
        fi
    done
    if ! ls /usr/lib/*/alsa-lib/libasound_module_pcm_pulse.so >/dev/null 2>&1; then
        say "ALSA's pulse plugin not found: apt-get install libasound2-plugins"
        exit 1
    fi
}

start() {
    need
    mkdir -p "$dir"
    chmod 700 "$dir"
    if ! answers; then
        # A server that died leaves its socket and pid file behind.
        stop_server
        rm -f "$socket" "$dir/pid"
        # -n: none of the default modules (no hardware detection, no suspend on idle, no
        # D-Bus); the socket is anonymous (no cookie), in our own folder. Real-time
        # scheduling where allowed (root), so a busy machine does not starve the sink.
        PULSE_RUNTIME_PATH="$dir" PULSE_STATE_PATH="$dir" pulseaudio -n --daemonize=yes \
            --exit-idle-time=-1 --disallow-exit --use-pid-file=yes \
            --realtime=yes --high-priority=yes --log-target="file:$dir/log" ${TIMPANIST_PULSE_LOG_LEVEL:+--log-level=$TIMPANIST_PULSE_LOG_LEVEL} \
            -L "module-native-protocol-unix socket=$socket auth-anonymous=1" \
            -L "module-null-sink sink_name=$sink rate=48000 format=float32le channels=2 sink_properties=device.description=timpanist_null" ||
            { say "pulseaudio did not start; its log:"; cat "$dir/log" >&2 2>/dev/null; exit 1; }
        for _ in $(seq 50); do
            answers && break
            sleep 0.1
        done
        if ! answers; then
            say "pulseaudio started but does not answer on $socket; its log:"
            cat "$dir/log" >&2 2>/dev/null || true
            exit 1
        fi
        say "started PulseAudio on $socket"
    fi
    if ! pa pactl list short sinks | grep -q "\b$sink\b"; then
        pa pactl load-module module-null-sink "sink_name=$sink" rate=48000 format=float32le \
            channels=2 >/dev/null
    fi
    pa pactl set-default-sink "$sink"
    route_alsa
    print_env
}

# Stop the server this script started (by its pid file), and wait until it is gone.
stop_server() {
    local pid
    pid=$(cat "$dir/pid" 2>/dev/null || true)
    if [ -n "$pid" ] && kill -0 "$pid" 2>/dev/null; then
        kill "$pid"
        for _ in $(seq 50); do
            kill -0 "$pid" 2>/dev/null || break
            sleep 0.1
        done
        kill -0 "$pid" 2>/dev/null && kill -9 "$pid" 2>/dev/null || true
        say "stopped PulseAudio ($pid)"
    fi
}

stop() {
    stop_server
    rm -f "$socket" "$dir/pid"
    if [ -e "$asoundrc" ] && grep -qF "$marker" "$asoundrc"; then
        rm "$asoundrc"
    fi
}

case "${1:-}" in
start) start ;;
stop) stop ;;
kill) stop_server ;;
env) print_env ;;
status) answers ;;
*)
    say "usage: $0 start|stop|kill|env|status"
    exit 2
    ;;
esac
