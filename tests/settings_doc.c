/* Prints docs/settings.md from the settings schema (cohfrac/settings.h):
 *   build/settings_doc > docs/settings.md
 * ctest settings_doc fails when the file in the tree differs. */
#include "cohfrac/settings.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static void print_value(const cf_setting *e, double v)
{
    if (e->kind == CF_SET_ENUM)
        printf("`\"%s\"`", e->names[(int)v]);
    else if (e->kind == CF_SET_BOOL)
        printf("`%s`", v ? "true" : "false");
    else
        printf("%.6g", v);
}

static void print_range(const cf_setting *e)
{
    if (e->names == cf_cohesive_law_names) { /* as many as the engine has files for */
        printf("`\"%s\"` and one per `src/engine/cohesive_<law>.c`", e->names[0]);
    } else if (e->kind == CF_SET_ENUM) {
        for (int k = 0; e->names[k]; k++)
            printf("%s`\"%s\"`", k ? ", " : "", e->names[k]);
    } else if (e->kind == CF_SET_BOOL) {
        printf("`true`, `false`");
    } else if (isinf(e->lo) && isinf(e->hi)) {
        printf("any");
    } else if (isinf(e->hi)) {
        printf("%s %g", e->lo_closed ? ">=" : ">", e->lo);
    } else {
        printf("%c%g, %g%c", e->lo_closed ? '[' : '(', e->lo, e->hi, e->hi_closed ? ']' : ')');
    }
}

int main(void)
{
    int n;
    const cf_setting *e = cf_settings(&n);
    cf_world_def d = cf_default_world_def();
    d.material = cf_default_material();
    d.solver = cf_default_solver();
    printf("# Settings: `material` and `solver`\n\n"
           "Generated from the schema in `include/cohfrac/settings.h` by "
           "`tests/settings_doc.c`\n(`build/settings_doc > docs/settings.md`; "
           "ctest `settings_doc` fails when this file differs).\n"
           "The schema gives the defaults (`cf_default_material`, `cf_default_solver`), the "
           "checks of\n`cf_world_def_check`, the scene reader and the resolved scene it "
           "writes back.  A scene\nleaves out any key to take its default; "
           "`src/io/include/cohfrac/scene.h` explains the keys at\nlength, and the other "
           "tables of a scene (bodies, obstacles, boundary, output).\n");
    static const char *const kinds[] = {"number", "integer", "boolean", "choice"};
    for (int t = 0; t < n; t++) { /* each table once, where it first appears */
        int first = 1;
        for (int j = 0; j < t; j++)
            first &= strcmp(e[j].table, e[t].table) != 0;
        if (!first)
            continue;
        printf("\n## `%s`\n\n| key | kind | default | allowed | unit | what |\n"
               "|---|---|---|---|---|---|\n", e[t].table);
        for (int i = t; i < n; i++) {
            if (strcmp(e[i].table, e[t].table) != 0 || e[i].kind == CF_SET_TABLE)
                continue;
            if (e[i].kind == CF_SET_CUSTOM) {
                printf("| `%s` | table | none | | | %s |\n", e[i].key, e[i].doc);
                continue;
            }
            printf("| `%s` | %s | ", e[i].key, kinds[e[i].kind]);
            if (e[i].def_from)
                printf("= `%s`", e[i].def_from);
            else
                print_value(&e[i], cf_setting_get(&e[i], &d));
            printf(" | ");
            print_range(&e[i]);
            printf(" | %s | %s |\n", e[i].unit, e[i].doc);
        }
    }
    return 0;
}
