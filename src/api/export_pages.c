#include "export_pages.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define ON_PAGE -2 /* lm_export_pages.index while it is made: the material has texels on the page */

int lm_export_tri_page(const lm_export_pages *ep, const lm_scene *s, const lm_atlas *a, uint32_t t)
{
    int p = lm_atlas_tri_page(a, t);
    return p >= 0 ? p : ep->first_page[s->tri_material[t]];
}

lm_status lm_export_pages_make(const lm_scene *s, const lm_atlas *a, lm_export_pages *ep, lm_error *err)
{
    memset(ep, 0, sizeof *ep);
    ep->pages = a->page_count > 0 ? a->page_count : 1;
    ep->materials = s->material_count;
    size_t cells = (size_t)ep->materials * ep->pages;
    ep->first_page = malloc(((size_t)ep->materials + 1) * sizeof *ep->first_page);
    ep->index = malloc((cells + 1) * sizeof *ep->index);
    ep->copy = malloc(2 * (cells + 1) * sizeof *ep->copy);
    if (!ep->first_page || !ep->index || !ep->copy) {
        lm_export_pages_free(ep);
        return lm_fail(err, LM_ERR_NOMEM, "export: no memory for the lightmap's %d pages", ep->pages);
    }
    for (size_t i = 0; i < cells; i++)
        ep->index[i] = -1;
    for (int m = 0; m < ep->materials; m++)
        ep->first_page[m] = ep->pages;
    for (uint32_t t = 0; t < s->tri_count; t++) { /* the pages with texels, then each material's first */
        int p = lm_atlas_tri_page(a, t), m = s->tri_material[t];
        if (p >= 0) {
            ep->index[(size_t)m * ep->pages + p] = ON_PAGE;
            ep->first_page[m] = p < ep->first_page[m] ? p : ep->first_page[m];
        }
    }
    for (int m = 0; m < ep->materials; m++) {
        ep->first_page[m] = ep->first_page[m] < ep->pages ? ep->first_page[m] : 0;
        ep->index[(size_t)m * ep->pages + ep->first_page[m]] = m; /* a material without texels: page 0 */
        for (int p = ep->first_page[m] + 1; p < ep->pages; p++)
            if (ep->index[(size_t)m * ep->pages + p] == ON_PAGE) {
                ep->copy[2 * ep->copies] = m, ep->copy[2 * ep->copies + 1] = p;
                ep->index[(size_t)m * ep->pages + p] = ep->materials + ep->copies++;
            }
    }
    return LM_OK;
}

void lm_export_pages_free(lm_export_pages *ep)
{
    free(ep->first_page);
    free(ep->index);
    free(ep->copy);
    memset(ep, 0, sizeof *ep);
}

void lm_export_lightmap_file(char *out, size_t size, const char *name, const lm_export_pages *ep, int page,
                             const char *what)
{
    if (ep->pages > 1)
        snprintf(out, size, "%s_lightmap_page%d%s", name, page, what);
    else
        snprintf(out, size, "%s_lightmap%s", name, what);
}
