/* Uses the installed C API (uh/uh.h, libuh) from plain C: packs a small closed mesh given as
 * arrays and queries it against itself. Prints "capi consumer ok" and exits 0 when it worked. */
#include <stdio.h>

#include <uh/uh.h>

int main(void) {
  static const double vertices[] = {-1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1, -1, -1, 1, 1, -1, 1, 1, 1, 1, -1, 1, 1};
  static const int32_t indices[] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                    1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};
  const double origin[3] = {0, 0, 0}, identity[4] = {1, 0, 0, 0};
  uh_tree_build_def def = uh_default_tree_build_def();
  uh_tree_id cube = {0};
  uh_query_result r;
  def.spheres = 100;
  if (uh_api_version() != UH_API_VERSION) return 1;
  if (uh_tree_build_from_arrays(vertices, 8, indices, 12, &def, &cube) != UH_OK) {
    fprintf(stderr, "%s\n", uh_last_error());
    return 1;
  }
  r.struct_size = sizeof r;
  if (uh_tree_query(cube, cube, origin, identity, &r) != UH_OK || !(r.volume > 0.0)) return 1;
  uh_tree_destroy(cube);
  printf("capi consumer ok (libuh %s)\n", uh_version_string());
  return 0;
}
