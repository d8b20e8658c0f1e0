#!/usr/bin/env bash
# The three "hosts" of the network tests, as Linux network namespaces: TAG-a 198.51.100.1,
# TAG-b 198.51.100.2, TAG-c 198.51.100.3 (eth0/24 and lo up each), joined by a bridge (br0) in a
# namespace of its own, TAG-br. One definition for every user: sourced by support/netns.sh (the
# integration tests and benches), run as a command by tests/docs/run_doc_blocks.py:
#   netns_hosts.sh make TAG     make them (exit 1 naming the step that failed)
#   netns_hosts.sh remove TAG   KILL every process in them and delete them (never fails)
# Root only.

netns_names() { echo "$1-br" "$1-a" "$1-b" "$1-c"; }  # TAG

netns_make() {  # TAG
  local tag=$1 n h i=1
  for n in $(netns_names "$tag"); do ip netns add "$n" || { echo "ip netns add $n failed" >&2; return 1; }; done
  ip -n "$tag-br" link add br0 type bridge &&
    ip -n "$tag-br" link set br0 up &&
    ip -n "$tag-br" link set lo up || { echo "the bridge in $tag-br failed" >&2; return 1; }
  for h in a b c; do
    ip -n "$tag-br" link add "v$h" type veth peer name eth0 netns "$tag-$h" &&
      ip -n "$tag-br" link set "v$h" master br0 up &&
      ip -n "$tag-$h" addr add "198.51.100.$i/24" dev eth0 &&
      ip -n "$tag-$h" link set eth0 up &&
      ip -n "$tag-$h" link set lo up ||  # lo down: omniORB would publish the host name
      { echo "host $h ($tag-$h) failed" >&2; return 1; }
    i=$((i + 1))
  done
}

netns_remove() {  # TAG
  local n p
  for n in $(netns_names "$1"); do
    for p in $(ip netns pids "$n" 2>/dev/null); do kill -KILL "$p" 2>/dev/null; done
  done
  sleep 0.2
  for n in $(netns_names "$1"); do ip netns del "$n" 2>/dev/null; done
  return 0
}

if [ "${BASH_SOURCE[0]}" = "$0" ]; then
  case "${1:-}:${2:-}" in
    make:?*) netns_make "$2" ;;
    remove:?*) netns_remove "$2" ;;
    *) echo "usage: netns_hosts.sh make|remove TAG" >&2; exit 2 ;;
  esac
fi
