#!/usr/bin/env bash
# apt-get with its arguments, waiting (up to NGWEAR_APT_WAIT seconds, 600 by default) while another package manager
# (an unattended upgrade, a second shell) holds one of apt's locks, then going on; any other failure at once.
set -uo pipefail
deadline=$((SECONDS + ${NGWEAR_APT_WAIT:-600}))
said=
until log=$(apt-get -o DPkg::Lock::Timeout=5 "$@" 2>&1); do
  if ! grep -q 'Could not get lock' <<<"$log" || [ "$SECONDS" -ge "$deadline" ]; then
    printf '%s\n' "$log" >&2
    exit 1
  fi
  [ -n "$said" ] || echo "ngwear: another package manager holds apt's lock: waiting for it" >&2
  said=1
  sleep 2
done
printf '%s\n' "$log"
