#!/bin/bash
# The set-up on systems other than Debian on x86-64, played on this one: a PATH without apt,
# dpkg, flock, nproc and sha256sum (as macOS and Fedora lack some of them), and stand-ins for
# the package managers that record what they are asked to install.
#   1. No package manager: the script stops at once with the complete line for apt, dnf and
#      brew (before any lock or build).
#   2. Homebrew (a stand-in brew that has nothing installed): it is asked for the complete brew
#      list, says that likwid is skipped and what that costs, then takes the build lock without
#      flock, hashes requirements.txt without sha256sum, counts the cores without nproc, builds
#      and runs chapter 01's tests.
#   3. dnf (stand-ins dnf and rpm): asked for the complete dnf list, the optional groups apart.
#   4. apt on a system whose sources lack likwid (arm64): the rest installs in one apt-get call
#      without likwid, which is named as skipped with what it costs.
# usage: test_setup_elsewhere.sh SOURCE_DIR (its build/release built, as after ./tutorial.sh build)
set -euo pipefail
root=$(cd "$1" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

# The expected lines, from the script's own lists (with the tools it normally has).
# shellcheck disable=SC1090
source <(sed '/^main "\$@"$/,$d' "$root/tutorial.sh")
expected_apt=$(install_line apt)
expected_dnf=$(install_line dnf)
expected_brew=$(install_line brew)
brew_required=$(packages_of brew required)
dnf_required=$(packages_of dnf required)

# A PATH of links to every command but the hidden ones.
hidden=" apt-get apt-cache dpkg-query dpkg flock nproc sha256sum dnf rpm brew "
mkdir -p "$tmp/bin"
IFS=: read -r -a dirs <<<"$PATH"
for dir in "${dirs[@]}"; do
  [ -d "$dir" ] || continue
  for tool in "$dir"/*; do
    name=$(basename "$tool")
    [[ "$hidden" == *" $name "* ]] && continue
    [ -x "$tool" ] && [ ! -e "$tmp/bin/$name" ] && ln -s "$tool" "$tmp/bin/$name"
  done
done
for name in $hidden; do [ ! -e "$tmp/bin/$name" ] || fail "$name is still on the test's PATH"; done

run() {  # run LOG PATH COMMAND...: the script with that PATH, its output in LOG, its status echoed
  local log=$1 path=$2
  shift 2
  set +e
  (cd "$root" && env PATH="$path" "$@") >"$log" 2>&1
  echo $?
  set -e
}

# 1. No package manager.
status=$(run "$tmp/none.log" "$tmp/bin" ./tutorial.sh test -L ch01)
[ "$status" -eq 1 ] || { cat "$tmp/none.log"; fail "without a package manager: exit $status, not 1"; }
for line in "$expected_apt" "$expected_dnf" "$expected_brew"; do
  grep -qF -- "$line" "$tmp/none.log" || { cat "$tmp/none.log"; fail "the line '$line' is not said"; }
done
grep -q "another command is building\|building (preset" "$tmp/none.log" &&
  fail "without a package manager the script went on to the lock or the build"
echo "PASS 1: no package manager: stops with the complete apt, dnf and brew lines"

# 2. Homebrew with nothing installed: the stand-in records each install.
mkdir -p "$tmp/brew"
cat >"$tmp/brew/brew" <<'BREW'
#!/bin/sh
case "$1" in
  list) exit 1 ;;
  install) shift; echo "$*" >>"$BREW_LOG"; exit 0 ;;
  --prefix) echo /nonexistent; exit 0 ;;
esac
exit 1
BREW
chmod +x "$tmp/brew/brew"
status=$(run "$tmp/brew.log" "$tmp/brew:$tmp/bin" BREW_LOG="$tmp/brew.calls" ./tutorial.sh test -L ch01)
[ "$status" -eq 0 ] || { tail -n 40 "$tmp/brew.log"; fail "with brew: exit $status"; }
[ "$(head -n 1 "$tmp/brew.calls")" = "$brew_required" ] ||
  fail "brew was asked for '$(head -n 1 "$tmp/brew.calls")', not '$brew_required'"
[ "brew install $(tr '\n' ' ' <"$tmp/brew.calls" | sed 's/ $//')" = "$expected_brew" ] ||
  fail "brew's calls $(tr '\n' ' ' <"$tmp/brew.calls") are not the complete line $expected_brew"
grep -q "Homebrew has no likwid: without it, no check of the roofline's roofs" "$tmp/brew.log" ||
  fail "likwid's absence on macOS is not named with its cost"
grep -q "tests passed" "$tmp/brew.log" || { tail -n 20 "$tmp/brew.log"; fail "with brew: no test ran"; }
[ ! -e "$root/build/release/.build.lock.d" ] || fail "the mkdir lock was left behind"
echo "PASS 2: brew: the complete list installed, likwid named, built and tested without flock, nproc, sha256sum"

# 3. dnf and rpm: nothing installed.
mkdir -p "$tmp/dnf"
printf '#!/bin/sh\nexit 1\n' >"$tmp/dnf/rpm"
printf '#!/bin/sh\n[ "$1" = install ] && shift 2 && echo "$*" >>"$DNF_LOG"\nexit 0\n' >"$tmp/dnf/dnf"
chmod +x "$tmp/dnf/rpm" "$tmp/dnf/dnf"
status=$(run "$tmp/dnf.log" "$tmp/dnf:$tmp/bin" DNF_LOG="$tmp/dnf.calls" ./tutorial.sh setup)
[ "$status" -eq 0 ] || { tail -n 40 "$tmp/dnf.log"; fail "with dnf: exit $status"; }
[ "$(head -n 1 "$tmp/dnf.calls")" = "$dnf_required" ] || fail "dnf was asked for $(head -n 1 "$tmp/dnf.calls")"
[ "sudo dnf install -y $(tr '\n' ' ' <"$tmp/dnf.calls" | sed 's/ $//')" = "$expected_dnf" ] ||
  fail "dnf's calls $(tr '\n' ' ' <"$tmp/dnf.calls") are not the complete line $expected_dnf"
echo "PASS 3: dnf: the complete list installed, each optional group apart"

# 4. apt whose sources lack likwid, as on arm64: every package reported missing, likwid
# without a candidate; the stand-in apt-get records the install.
mkdir -p "$tmp/apt"
printf '#!/bin/sh\nexit 1\n' >"$tmp/apt/dpkg-query"
cat >"$tmp/apt/apt-cache" <<'APT'
#!/bin/sh
[ "$2" = likwid ] && { echo "N: Unable to locate package likwid"; exit 0; }
echo "  Candidate: 1.0"
APT
printf '#!/bin/sh\n[ "$1" = install ] && echo "$*" >>"$APT_LOG"\nexit 0\n' >"$tmp/apt/apt-get"
chmod +x "$tmp/apt/dpkg-query" "$tmp/apt/apt-cache" "$tmp/apt/apt-get"
# (the package step alone: the build was checked above)
sed '/^main "\$@"$/,$d' "$root/tutorial.sh" >"$tmp/packages.sh"
echo "SKIPPED_PACKAGES=$tmp/skipped.list; install_system_packages" >>"$tmp/packages.sh"
status=$(run "$tmp/apt.log" "$tmp/apt:$tmp/bin" APT_LOG="$tmp/apt.calls" bash "$tmp/packages.sh")
[ "$status" -eq 0 ] || { cat "$tmp/apt.log"; fail "apt without likwid: exit $status"; }
[ "$(wc -l <"$tmp/apt.calls")" -eq 1 ] || fail "apt-get install ran $(wc -l <"$tmp/apt.calls") times, not once"
want="install -y -qq --no-install-recommends ${expected_apt#sudo apt-get install -y }"
want=${want/ likwid/}
[ "$(sed 's/ $//' "$tmp/apt.calls")" = "$want" ] || fail "apt-get was asked: $(cat "$tmp/apt.calls"), not: $want"
grep -q "skipped likwid (apt has none for .* in this system's sources): without it, no check of the roofline's roofs" \
  "$tmp/apt.log" || { cat "$tmp/apt.log"; fail "likwid's absence is not named with its cost"; }
grep -qx "likwid:likwid" <(tr ' ' '\n' <"$tmp/skipped.list") || fail "likwid is not remembered as skipped"
echo "PASS 4: apt without likwid: the rest installed in one call, likwid named with its cost"
