/* The smallest complete use of the C ABI: points in, oriented mesh out.
 * Build: cc reconstruct_minimal.c $(pkg-config --cflags --libs gmpu)
 * Run:   ./a.out examples/data/bunny.ply bunny_mesh.ply */
#include <stdio.h>

#include <gmpu/gmpu.h>

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: %s POINTS.ply MESH.ply\n", argv[0]);
        return 2;
    }
    gmpu_points *cloud = NULL;
    gmpu_surface *surface = NULL;
    gmpu_mesh *mesh = NULL;
    int ok = gmpu_points_read(argv[1], &cloud) == GMPU_OK &&
             gmpu_surface_create(&surface) == GMPU_OK &&
             gmpu_surface_set_param(surface, GMPU_PARAM_ERROR, 0.002) == GMPU_OK &&
             gmpu_surface_set_points_f64(surface, gmpu_points_positions(cloud),
                                         gmpu_points_count(cloud), 0) == GMPU_OK &&
             gmpu_surface_fit(surface) == GMPU_OK &&       /* octree of local quadrics */
             gmpu_surface_orient(surface) == GMPU_OK &&    /* belief propagation, outward */
             gmpu_surface_polygonize(surface, &mesh) == GMPU_OK &&
             gmpu_mesh_write(mesh, argv[2]) == GMPU_OK;
    if (ok) {
        double centre[3] = {0, 0, 0}, f = 0;
        gmpu_surface_evaluate(surface, centre, 1, &f, NULL); /* f > 0 inside */
        printf("%zu triangles written to %s; f(0,0,0) = %g\n",
               gmpu_mesh_triangle_count(mesh), argv[2], f);
    } else {
        fprintf(stderr, "gmpu: %s\n", gmpu_last_error()); /* names the status and the problem */
    }
    gmpu_mesh_destroy(mesh);
    gmpu_surface_destroy(surface);
    gmpu_points_destroy(cloud);
    return ok ? 0 : 1;
}
