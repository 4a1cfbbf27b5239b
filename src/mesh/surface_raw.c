/* cohfrac — the surface hand-over file of cohfrac-repair (surface_raw.h). */
#include "surface_raw.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define RAW_MAGIC "cohfrac-surface 1\n"

cf_status cf_surface_write_raw(const cf_surface *s, const char *path, cf_error *err)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return cf_error_set(err, cf_status_of_errno(errno, CF_ERR_OUTPUT),
                            "%s: cannot write (%s)", path, strerror(errno));
    int bad = fputs(RAW_MAGIC, f) < 0 || fwrite(&s->n_verts, sizeof(int), 1, f) != 1 ||
              fwrite(&s->n_tris, sizeof(int), 1, f) != 1 ||
              fwrite(s->v, 3 * sizeof(double), (size_t)s->n_verts, f) != (size_t)s->n_verts ||
              fwrite(s->tri, 3 * sizeof(int), (size_t)s->n_tris, f) != (size_t)s->n_tris;
    bad |= fclose(f) != 0;
    return bad ? cf_error_set(err, CF_ERR_OUTPUT, "%s: write failed (disk full?)", path) : CF_OK;
}

cf_status cf_surface_read_raw(const char *path, cf_surface *s, cf_error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return cf_error_set(err, cf_status_of_errno(errno, CF_ERR_FILE_OPEN),
                            "%s: cannot read (%s)", path, strerror(errno));
    char magic[sizeof RAW_MAGIC] = "";
    int nv = -1, nt = -1;
    cf_status st = CF_OK;
    if (fread(magic, 1, sizeof RAW_MAGIC - 1, f) != sizeof RAW_MAGIC - 1 ||
        strcmp(magic, RAW_MAGIC) != 0 || fread(&nv, sizeof nv, 1, f) != 1 ||
        fread(&nt, sizeof nt, 1, f) != 1 || nv < 0 || nt < 0) {
        st = cf_error_set(err, CF_ERR_MESH_PARSE, "%s: not a surface from cohfrac-repair", path);
    } else {
        s->v = malloc((size_t)(nv > 0 ? nv : 1) * 3 * sizeof(double));
        s->tri = malloc((size_t)(nt > 0 ? nt : 1) * 3 * sizeof(int));
        s->n_verts = nv, s->n_tris = nt;
        if (!s->v || !s->tri)
            st = cf_error_set(err, CF_ERR_NOMEM, "out of memory reading %s", path);
        else if (fread(s->v, 3 * sizeof(double), (size_t)nv, f) != (size_t)nv ||
                 fread(s->tri, 3 * sizeof(int), (size_t)nt, f) != (size_t)nt)
            st = cf_error_set(err, CF_ERR_MESH_PARSE, "%s: cut short", path);
        for (int i = 0; st == CF_OK && i < 3 * nt; i++)
            if (s->tri[i] < 0 || s->tri[i] >= nv)
                st = cf_error_set(err, CF_ERR_MESH_PARSE, "%s: a corner out of range", path);
        if (st != CF_OK) {
            free(s->v), free(s->tri);
            memset(s, 0, sizeof *s);
        }
    }
    fclose(f);
    return st;
}
