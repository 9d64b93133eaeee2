#!/usr/bin/env bash
# `make install` into a scratch prefix, then build and run a project outside the tree that finds the
# installed package with find_package(rsg): the public headers, libraries and config are complete.
set -euo pipefail
source_dir=${1:?usage: install_consumer_test.sh SOURCE_DIR BUILD_DIR}
build_dir=${2:?usage: install_consumer_test.sh SOURCE_DIR BUILD_DIR}
# The DDS domain of the consumers that open one: the one tests/support/test_domain.py holds for us.
domain=${RSG_TEST_DOMAIN:?run it through tests/support/test_domain.py, which takes a domain}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

cmake --install "$build_dir" --prefix "$work/prefix" > "$work/install.log"
# Only the public layers are installed: no gateway or simulator internals (the embedded gateway's
# one header is public, and rsg/error.hpp, the exception hierarchy of every layer; idl/ holds the
# generated types, .hpp files with fastddsgen 4).
installed=$(cd "$work/prefix/include/rsg" && find . -name '*.hpp' | sort)
for header in $installed; do
  case "$header" in ./error.hpp | ./wire/* | ./transport/* | ./dds/* | ./idl/* | ./gateway/embedded_gateway.hpp) ;; *) echo "FAIL: internal header installed: $header"; exit 1 ;; esac
done
# No installed header reaches for what is not installed: rsg's own headers include each other as
# "rsg/...", never a header of src/ (src/<layer>/internal/ or any other, CONTRIBUTING.md), and name
# no internal namespace but to befriend (wire::internal::FrameDecoder, which stays in src/wire).
if grep -rn '#include "' "$work/prefix/include/rsg" --include='*.hpp' --exclude-dir=idl | grep -v '#include "rsg/'; then
  echo "FAIL: an installed header includes one that is not installed"; exit 1
fi
if grep -rn 'internal::' "$work/prefix/include/rsg" --include='*.hpp' --exclude-dir=idl | grep -v 'friend class internal::'; then
  echo "FAIL: an installed header uses an internal name"; exit 1
fi
# The package exports what a consumer links and nothing internal (CONTRIBUTING.md, "Layers"): the
# gateway's internals travel inside rsg::embedded_gateway's archive, the generated types inside rsg::dds's.
exported=$(cat "$work"/prefix/lib*/cmake/rsg/rsg*Targets.cmake | sed -n 's/^add_library(\(rsg::[a-z_]*\) .*/\1/p' | sort | tr '\n' ' ')
[[ "$exported" == "rsg::dds rsg::eigen rsg::embedded_gateway rsg::transport rsg::wire " ]] ||
  { echo "FAIL: the package exports $exported"; exit 1; }
archives=$(cd "$work"/prefix/lib* && ls *.a | sort | tr '\n' ' ')
[[ "$archives" == "librsg_dds.a librsg_embedded_gateway.a librsg_transport.a librsg_wire.a " ]] ||
  { echo "FAIL: the archives installed are $archives"; exit 1; }
for tool in rsg_gateway rsg_sim rsg_echo rsg_frame rsg_record rsg_replay rsg_view; do
  [[ -x "$work/prefix/bin/$tool" ]] || { echo "FAIL: $tool not installed"; exit 1; }
done
[[ -f "$work/prefix/share/rsg/idl/RobotState.idl" ]] || { echo "FAIL: IDL not installed"; exit 1; }

cmake -S "$source_dir/tests/packaging/consumer" -B "$work/build" -DCMAKE_PREFIX_PATH="$work/prefix" \
  > "$work/configure.log" || { cat "$work/configure.log"; exit 1; }
cmake --build "$work/build" > "$work/build.log" 2>&1 || { cat "$work/build.log"; exit 1; }
# ROS 2's default standard: the package's usage requirement lifts it to what the headers need.
cmake -S "$source_dir/tests/packaging/consumer" -B "$work/build17" -DCMAKE_PREFIX_PATH="$work/prefix" \
  -DCMAKE_CXX_STANDARD=17 > "$work/configure17.log" || { cat "$work/configure17.log"; exit 1; }
cmake --build "$work/build17" > "$work/build17.log" 2>&1 || { cat "$work/build17.log"; exit 1; }
# The client libraries alone ask for no component, and find none of the components' dependencies.
cmake -S "$source_dir/tests/packaging/consumer" -B "$work/build_core" -DCMAKE_PREFIX_PATH="$work/prefix" \
  -DRSG_CONSUMER_EMBEDDED=OFF -DCMAKE_DISABLE_FIND_PACKAGE_spdlog=ON -DCMAKE_DISABLE_FIND_PACKAGE_fmt=ON \
  -DCMAKE_DISABLE_FIND_PACKAGE_yaml-cpp=ON -DCMAKE_DISABLE_FIND_PACKAGE_Eigen3=ON \
  -DCMAKE_DISABLE_FIND_PACKAGE_nlohmann_json=ON > "$work/configure_core.log" || { cat "$work/configure_core.log"; exit 1; }
cmake --build "$work/build_core" > "$work/build_core.log" 2>&1 || { cat "$work/build_core.log"; exit 1; }
"$work/build/consumer"
# A view, with the installed profiles, on a domain of its own (Fast DDS 2 or 3: what rsg was built on).
"$work/build/view_consumer" "$work/prefix/share/rsg/xml_profiles" "$domain"
# The embedded gateway from the installed package, with the installed profiles, on its own domain.
"$work/build/embedded_consumer" "$work/prefix/share/rsg/xml_profiles" "$domain"
echo "install_consumer: OK ($(echo "$installed" | wc -w) public headers)"
