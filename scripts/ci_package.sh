#!/bin/sh
# The install and the Debian package as a user gets them (docs/install.md), on a built
# build/release (./scripts/build.sh):
#  1. `cmake --install` into a prefix, then moved (the tree is relocatable): `emaki --version`,
#     the man page, the Python module by PYTHONPATH, the OpenImageIO plugin found from the binary
#     and from the module (and one line naming a library it needs that is missing), and a C++
#     project built with find_package(emaki) against the tree;
#  2. cpack's emaki_<version>_amd64.deb (runtime dependencies only) installed with apt-get; from
#     a folder outside the checkout: `emaki run` on the installed example (two frames, small
#     size), `import emaki` with /usr/bin/python3 and no PYTHONPATH; `apt-get remove` then
#     leaves no file of it behind.
# apt-get needs root (or sudo).
set -e
ROOT=$(cd "$(dirname "$0")/.." && pwd)
B=$ROOT/build/release
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
WORK=$(mktemp -d /tmp/emaki_package.XXXXXX)
installed=""
cleanup() {
  [ -n "$installed" ] && $SUDO apt-get purge -y -qq emaki >/dev/null 2>&1
  rm -rf "$WORK"
}
trap cleanup EXIT
step() { echo "ci_package: $*"; }
fail() {
  echo "ci_package: FAIL: $*"
  exit 1
}
# The OpenImageIO plugin a command loads (the dynamic loader's own record of it).
plugin_loaded() {
  LD_DEBUG=files "$@" 2>&1 >/dev/null | sed -n 's/.*file=\([^ ]*libemaki_io_oiio\.so\).*/\1/p' |
    head -n 1
}

# ---- 1. a prefix ------------------------------------------------------------------------------
# Up to date first (nothing to do after ./run_tests.sh): cpack builds `all` before packing, and the
# prefix and the package must hold the same build.
cmake --build "$B" -j"$(nproc)" >/dev/null
# Over an older install: a module built for another Python does not stay beside the new one.
stale=$WORK/installed/lib/python3/dist-packages/emaki.cpython-39-x86_64-linux-gnu.so
mkdir -p "$(dirname "$stale")"
: >"$stale"
cmake --install "$B" --prefix "$WORK/installed" >/dev/null
[ ! -e "$stale" ] || fail "an older Python module stayed in the prefix"
mv "$WORK/installed" "$WORK/prefix"
P=$WORK/prefix
version=$("$P/bin/emaki" --version)
step "cmake --install, moved: $version"
grep -q '^\.SS emaki farm$' "$P/share/man/man1/emaki.1" || fail "no 'emaki farm' in the man page"
test -f "$P/share/emaki/blender/emaki_blender.zip" || fail "no Blender add-on zip"
test -f "$P/share/emaki/examples/fox/shot.toml" || fail "no example shot"
# emaki's own EXRs and PNGs need no plugin; a TIFF does.
"$P/bin/emaki" template --size 32x24 --aa 1 --out "$WORK/template" 2>/dev/null
T=$WORK/template/template.png
synth_tif() { "$P/bin/emaki" synth -style "$T" -guide "$T" "$T" -output "$1" --quiet; }
plugin=$(plugin_loaded "$P/bin/emaki" synth -style "$T" -guide "$T" "$T" \
  -output "$WORK/template/out.tif" --quiet)
[ "$plugin" = "$P/bin/../lib/emaki/libemaki_io_oiio.so" ] || fail "emaki loaded '$plugin'"
plugin=$(PYTHONPATH=$P/lib/python3/dist-packages plugin_loaded /usr/bin/python3 -c "
import inspect, sys, emaki
assert 'emaki ' + emaki.__version__ == sys.argv[1], emaki.__version__
assert str(inspect.signature(emaki.read_image)) == '(path, channels=None)'
assert emaki.__file__.startswith(sys.argv[2]), emaki.__file__
emaki.read_image(sys.argv[3])" "$version" "$P/lib/python3/dist-packages/" "$WORK/template/out.tif")
case "$plugin" in
  "$P/lib/python3/dist-packages/../../emaki/libemaki_io_oiio.so") ;;
  *) fail "the Python module loaded '$plugin'" ;;
esac
step "the binary and the Python module load the prefix's OpenImageIO plugin"
# A library the plugin needs is missing: one line naming it, exit 1, no output file.
mv "$P/lib/emaki/libemaki_io_oiio.so" "$WORK/plugin.so"
printf 'int emaki_gone(void) { return 1; }\n' >"$WORK/gone.c"
printf 'int emaki_gone(void);\nint emaki_oiio_backend(void) { return emaki_gone(); }\n' \
  >"$WORK/plugin.c"
cc -shared -fPIC -o "$WORK/libemaki_gone.so" "$WORK/gone.c"
cc -shared -fPIC -o "$P/lib/emaki/libemaki_io_oiio.so" "$WORK/plugin.c" -L"$WORK" -lemaki_gone
rm "$WORK/libemaki_gone.so"
if synth_tif "$WORK/broken.tif" 2>"$WORK/err"; then
  fail "emaki ran with a plugin whose library is missing"
fi
[ "$(wc -l <"$WORK/err")" -eq 1 ] && grep -q "libemaki_gone.so: cannot open" "$WORK/err" ||
  fail "not one line naming the missing library: $(cat "$WORK/err")"
[ ! -e "$WORK/broken.tif" ] || fail "output written without the plugin"
mv "$WORK/plugin.so" "$P/lib/emaki/libemaki_io_oiio.so"
step "a library missing under the plugin: $(cat "$WORK/err")"
cmake -S "$ROOT/tests/install_consumer" -B "$WORK/consumer" -DCMAKE_PREFIX_PATH="$P" \
  -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$WORK/consumer" >/dev/null
step "find_package(emaki): $("$WORK/consumer/consumer" "$P/share/emaki/examples/fox/shot.toml")"

# ---- 2. the Debian package --------------------------------------------------------------------
(cd "$B" && rm -f emaki_*.deb emaki-dev_*.deb && cpack -G DEB >/dev/null)
deb=$(ls "$B"/emaki_*_amd64.deb)
step "$(basename "$deb"): Depends: $(dpkg-deb -f "$deb" Depends)"
if dpkg-deb -f "$deb" Depends | tr ',' '\n' | grep -q -- '-dev\b'; then
  fail "the runtime package depends on a -dev package"
fi
# The binary links OpenColorIO (src/colour): dpkg-shlibdeps must have found its runtime package.
dpkg-deb -f "$deb" Depends | grep -q 'libopencolorio' ||
  fail "the runtime package does not depend on OpenColorIO's library"
[ ! -e /usr/bin/emaki ] || fail "/usr/bin/emaki exists before the install"
installed=yes
$SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "$deb" >/dev/null
mkdir -p "$WORK/user"
cd "$WORK/user"
[ "$(emaki --version)" = "$version" ] || fail "installed: $(emaki --version)"
cp -r /usr/share/emaki/examples .
sed -i 's/^size = .*/size = [192, 108]/' examples/fox/shot.toml
emaki run examples/fox/shot.toml --frames 0-1 --no-previews 2>run.log ||
  { tail -n 5 run.log; fail "emaki run on the installed example"; }
n=$(ls examples/fox/out/composite | grep -c '^frame_.*\.png$')
[ "$n" -eq 2 ] || fail "$n composited frames, not 2"
grep -q "^emaki_version = ${version#emaki }$" examples/fox/out/layers/base/.emaki-manifest ||
  fail "no version line in the layer's manifest"
step "emaki run on the installed example: 2 frames"
env -u PYTHONPATH /usr/bin/python3 -c "
import emaki
assert emaki.__file__.startswith('/usr/lib/python3/dist-packages/'), emaki.__file__
print('ci_package: import emaki:', emaki.__version__)"
cd "$ROOT"
$SUDO apt-get remove -y -qq emaki >/dev/null
installed=""
left=$(ls -d /usr/bin/emaki /usr/lib/emaki /usr/share/emaki /usr/share/man/man1/emaki.1* \
  /usr/lib/python3/dist-packages/emaki* 2>/dev/null || true)
[ -z "$left" ] || fail "left after apt-get remove: $left"
# dpkg keeps a removed package's record ("rc") until purged: none is left of this one either.
$SUDO dpkg --purge emaki >/dev/null
step "apt-get remove emaki: nothing left"
