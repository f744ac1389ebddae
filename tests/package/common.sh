# Shared by the package tests (sourced): fail() naming the test, $version, a clean work folder.
# usage: package_test_init NAME WORK_DIR
source "$(dirname "${BASH_SOURCE[0]}")/../../scripts/common.sh"
package_test_init() {
  test_name=$1
  version=$(uh_project_version)
  rm -rf "$2"
  mkdir -p "$2"
}
fail() { echo "$test_name: $*" >&2; exit 1; }
