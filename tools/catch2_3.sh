#!/usr/bin/env bash
# Catch2 3 beside Debian 12's Catch2 2, without replacing it: downloads Debian's
# bookworm-backports package (libcatch2-dev 3.7.1, the series Ubuntu 24.04, Fedora and
# Homebrew ship) and unpacks it under build/deps/catch2-3, where the `catch2-3` CMake preset
# finds it through CMAKE_PREFIX_PATH. The system is left as it was: apt runs with its own
# source list, package lists and cache inside that folder, and nothing is installed.
#
#     tools/catch2_3.sh            # prints the prefix (build/deps/catch2-3/usr)
#
# Idempotent: a second run finds the unpacked package and prints its prefix. Needs apt-get
# and dpkg-deb (Debian 12); elsewhere install Catch2 3 from the system's packages instead
# (README, "Other systems") and configure with the `release` preset, which finds it there.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
DEST="${CATCH2_3_DIR:-$ROOT/build/deps/catch2-3}"
SUITE="${CATCH2_3_SUITE:-bookworm-backports}"
MIRROR="${DEBIAN_MIRROR:-http://deb.debian.org/debian}"
KEYRING=/usr/share/keyrings/debian-archive-keyring.gpg
PREFIX="$DEST/usr"

if [ -f "$PREFIX/lib/cmake/Catch2/Catch2ConfigVersion.cmake" ]; then
  echo "$PREFIX"
  exit 0
fi
for tool in apt-get dpkg-deb; do
  if ! command -v "$tool" >/dev/null; then
    echo "tools/catch2_3.sh: no $tool here: it fetches Debian's package only. Install Catch2 3" >&2
    echo "from this system's packages (README, \"Other systems\") and use the release preset." >&2
    exit 1
  fi
done

apt_dir="$DEST/apt"
mkdir -p "$apt_dir/lists/partial" "$apt_dir/cache/archives/partial"
signed_by=""
[ -f "$KEYRING" ] && signed_by="[signed-by=$KEYRING] "
echo "deb ${signed_by}$MIRROR $SUITE main" >"$apt_dir/sources.list"
# Only this source, these lists and this cache: the system's apt state is read, never written.
apt_options=(
  -o "Dir::Etc::SourceList=$apt_dir/sources.list" -o "Dir::Etc::SourceParts=$apt_dir/none"
  -o "Dir::State::Lists=$apt_dir/lists" -o "Dir::Cache=$apt_dir/cache"
  -o "Debug::NoLocking=true" -o "APT::Sandbox::User=$(id -un)"
)
echo "tools/catch2_3.sh: fetching libcatch2-dev from $SUITE into ${DEST#"$ROOT"/}" >&2
apt-get "${apt_options[@]}" -qq update >&2
(cd "$apt_dir" && rm -f libcatch2-dev_*.deb &&
  apt-get "${apt_options[@]}" -qq download "libcatch2-dev/$SUITE" >&2)
deb=$(ls "$apt_dir"/libcatch2-dev_*.deb)
version=$(dpkg-deb -f "$deb" Version)
case "$version" in
  3.*) ;;
  *)
    echo "tools/catch2_3.sh: $SUITE has libcatch2-dev $version, not Catch2 3" >&2
    exit 1
    ;;
esac
dpkg-deb -x "$deb" "$DEST"
echo "tools/catch2_3.sh: Catch2 $version in ${PREFIX#"$ROOT"/}" >&2
echo "$PREFIX"
