/* The lightmap's pages through the public API: where each lies in the atlas, which page a triangle or a
 * surface is on, and one page's read (docs/api.md, "Lightmap pages"). */
#include <lmgi.h>

#include <string.h>

#include "lmgi_scene.h"
#include "lmgi_updater.h"

int lmgi_page_rect(const lmgi_scene *sc, int page, int rect[4])
{
    if (!rect)
        return 0;
    memset(rect, 0, 4 * sizeof *rect);
    if (!sc || page < 0 || page >= sc->atlas.page_count)
        return 0;
    lm_atlas_page_rect(&sc->atlas, page, rect);
    return 1;
}

int lmgi_triangle_lightmap_page(const lmgi_scene *sc, uint32_t tri, float uv[6])
{
    if (!sc || !uv || tri >= sc->scene->tri_count || sc->atlas.tri_chart[tri] < 0)
        return -1;
    int page = lm_atlas_tri_page(&sc->atlas, tri);
    for (int k = 0; k < 3; k++)
        lm_atlas_page_uv(&sc->atlas, page, sc->atlas.corner_uv + 6 * (size_t)tri + 2 * k, uv + 2 * k);
    return page;
}

int lmgi_surface_page(const lmgi_scene *sc, int surface)
{
    if (!sc || surface < 0 || surface >= sc->atlas.surface_count || !sc->atlas.surface_chart_count[surface])
        return -1;
    const lm_atlas *a = &sc->atlas;
    int first = a->surface_first_chart[surface], page = a->charts[first].page;
    for (int c = first + 1; c < first + a->surface_chart_count[surface]; c++)
        if (a->charts[c].page != page)
            return -1;
    return page;
}

lmgi_status lmgi_get_lightmap_page(lmgi_updater *u, lmgi_lightmap kind, int page, float *rgba, size_t floats,
                                   lmgi_error *err)
{
    if (!u)
        return lm_api_refuse(err, "lmgi_get_lightmap_page: the updater is NULL");
    const lmgi_scene *sc = lm_updater_scene(u);
    int rect[4];
    if (!lmgi_page_rect(sc, page, rect))
        return lm_api_refuse(err, "lmgi_get_lightmap_page: page %d is not one of the scene's %d pages (0 to %d)", page,
                             sc->atlas.page_count, sc->atlas.page_count - 1);
    size_t need = 4 * (size_t)rect[2] * rect[3];
    if (!rgba)
        return lm_api_refuse(err, "lmgi_get_lightmap_page: rgba is NULL");
    if (floats < need)
        return lm_api_refuse(err, "lmgi_get_lightmap_page: the buffer holds %zu floats; the %d x %d page needs %zu",
                             floats, rect[2], rect[3], need);
    return lmgi_get_lightmap_rect(u, kind, rect, rgba, floats, err);
}
