// Writes src/pvr/shading/ggx_albedo_table.inc to stdout (shading/ggx_albedo_generator.h):
//   cmake --build build --target pvr_ggx_albedo_table && build/pvr_ggx_albedo_table > src/pvr/shading/ggx_albedo_table.inc
#include <cstdio>

#include "pvr/shading/ggx_albedo_generator.h"

int main() {
  const pvr::GgxAlbedoTable t = pvr::makeGgxAlbedoTable();
  std::printf("// The GGX albedo table of shading/ggx_albedo.h: makeGgxAlbedoTable() of\n"
              "// shading/ggx_albedo_generator.h (GgxAlbedo.TableIsTheGeneratorsOutput checks it).\n");
  std::printf("// E(mu_i, alpha_j) at [j * %d + i]: mu_i = i / %d, alpha_j = (j / %d)^2.\n", pvr::kGgxAlbedoSize,
              pvr::kGgxAlbedoSize - 1, pvr::kGgxAlbedoSize - 1);
  std::printf("#define PVR_GGX_ALBEDO \\\n");
  for (size_t k = 0; k < t.albedo.size(); ++k)
    std::printf("%s%#.9gf,%s", k % 8 == 0 ? "  " : " ", double(t.albedo[k]), k % 8 == 7 ? " \\\n" : "");
  std::printf("\n// E_avg(alpha_j) of the rows interpolated in mu.\n#define PVR_GGX_AVERAGE_ALBEDO \\\n");
  for (size_t k = 0; k < t.averageAlbedo.size(); ++k)
    std::printf("%s%#.9gf,%s", k % 8 == 0 ? "  " : " ", double(t.averageAlbedo[k]),
                k % 8 == 7 && k + 1 < t.averageAlbedo.size() ? " \\\n" : "");
  std::printf("\n");
  return 0;
}
