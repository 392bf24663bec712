/* What a program that uses an installed gmpu looks like: it includes <gmpu/gmpu.h>, links
 * the library however its build system finds it, and reconstructs a small sphere.
 * tests/consumers/run.sh builds it through pkg-config (shared and static), CMake and a meson
 * subproject. Prints "<version> <triangle count>"; exit 1 on any failure. */
#include <math.h>
#include <stdio.h>

#include <gmpu/gmpu.h>

int main(void) {
    enum { N = 800 };
    static double xyz[3 * N];
    /* A Fibonacci sphere: evenly spread points on the unit sphere. */
    for (int i = 0; i < N; ++i) {
        const double z = 1.0 - (2.0 * i + 1.0) / N, r = sqrt(1.0 - z * z);
        const double a = 2.399963229728653 * i;
        xyz[3 * i] = r * cos(a);
        xyz[3 * i + 1] = r * sin(a);
        xyz[3 * i + 2] = z;
    }
    gmpu_surface *surface = NULL;
    gmpu_mesh *mesh = NULL;
    const int ok = gmpu_surface_create(&surface) == GMPU_OK &&
                   gmpu_surface_set_param(surface, GMPU_PARAM_RESOLUTION, 24) == GMPU_OK &&
                   gmpu_surface_set_points_f64(surface, xyz, N, 0) == GMPU_OK &&
                   gmpu_surface_fit(surface) == GMPU_OK && gmpu_surface_orient(surface) == GMPU_OK &&
                   gmpu_surface_polygonize(surface, &mesh) == GMPU_OK;
    if (ok)
        printf("%s %zu\n", gmpu_version_string(), gmpu_mesh_triangle_count(mesh));
    else
        fprintf(stderr, "consumer: %s\n", gmpu_last_error());
    gmpu_mesh_destroy(mesh);
    gmpu_surface_destroy(surface);
    return ok ? 0 : 1;
}
