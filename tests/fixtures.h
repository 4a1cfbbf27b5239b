/* Shared test fixtures: structured boxes and the two-tet pair, reading a
 * file whole, removing a temporary directory tree. */
#ifndef COHFRAC_TEST_FIXTURES_H
#define COHFRAC_TEST_FIXTURES_H

#include "cohfrac/mesh.h"

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* rm -r: a test's own temporary directory tree (links are not followed). */
static inline void fixture_remove_tree(const char *path)
{
    struct stat sb;
    if (lstat(path, &sb) != 0)
        return;
    if (!S_ISDIR(sb.st_mode)) {
        unlink(path);
        return;
    }
    DIR *d = opendir(path);
    if (d) {
        struct dirent *e;
        while ((e = readdir(d)) != NULL) {
            if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
                continue;
            char child[1024];
            if (snprintf(child, sizeof child, "%s/%s", path, e->d_name) < (int)sizeof child)
                fixture_remove_tree(child);
        }
        closedir(d);
    }
    rmdir(path);
}

/* The whole file as a NUL-terminated string (malloc'd), or NULL. */
static inline char *fixture_read_file(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *b = n >= 0 ? malloc((size_t)n + 1) : NULL;
    size_t got = b ? fread(b, 1, (size_t)n, f) : 0;
    if (b)
        b[got] = '\0';
    fclose(f);
    return b;
}

/* Box [0,lx]x[0,ly]x[0,lz] in nx*ny*nz cells, 6 tets per cell (Kuhn
 * subdivision along the main diagonal), every tet positively oriented. */
static inline void fixture_box(cf_mesh *m, int nx, int ny, int nz, double lx, double ly, double lz)
{
    memset(m, 0, sizeof *m);
    m->n_nodes = (nx + 1) * (ny + 1) * (nz + 1);
    m->n_tets = 6 * nx * ny * nz;
    m->x = malloc((size_t)m->n_nodes * 3 * sizeof(double));
    m->tets = malloc((size_t)m->n_tets * 4 * sizeof(int));
#define NODE(i, j, k) (((k) * (ny + 1) + (j)) * (nx + 1) + (i))
    for (int k = 0; k <= nz; k++)
        for (int j = 0; j <= ny; j++)
            for (int i = 0; i <= nx; i++) {
                double *x = &m->x[3 * NODE(i, j, k)];
                x[0] = lx * i / nx, x[1] = ly * j / ny, x[2] = lz * k / nz;
            }
    static const int perm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    int t = 0;
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++)
                for (int p = 0; p < 6; p++) {
                    int c[3] = {i, j, k}, *T = &m->tets[4 * t++];
                    T[0] = NODE(c[0], c[1], c[2]);
                    for (int s = 0; s < 3; s++) {
                        c[perm[p][s]]++;
                        T[s + 1] = NODE(c[0], c[1], c[2]);
                    }
                    const double *a = &m->x[3 * T[0]], *b = &m->x[3 * T[1]], *cc = &m->x[3 * T[2]],
                                 *d = &m->x[3 * T[3]];
                    if (cf_tet_volume(a, b, cc, d) < 0) {
                        int tmp = T[1];
                        T[1] = T[2], T[2] = tmp;
                    }
                }
#undef NODE
}

/* Two unit-ish tets sharing the facet (0,1,2): apexes 3 (above) and 4 (below). */
static inline void fixture_two_tets(cf_mesh *m)
{
    static const double x[5][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.2, 0.2, 1}, {0.3, 0.3, -1}};
    static const int t[2][4] = {{0, 1, 2, 3}, {0, 2, 1, 4}};
    memset(m, 0, sizeof *m);
    m->n_nodes = 5, m->n_tets = 2;
    m->x = malloc(sizeof x), m->tets = malloc(sizeof t);
    for (int i = 0; i < 15; i++)
        m->x[i] = x[i / 3][i % 3];
    for (int i = 0; i < 8; i++)
        m->tets[i] = t[i / 4][i % 4];
}

#endif
