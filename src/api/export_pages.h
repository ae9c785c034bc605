/* Which lightmap page each part of lmgi_export_gltf's document samples, for a level of several pages
 * (docs/api.md, "Lightmap pages"): a primitive per node, material and page, TEXCOORD_1 over its page,
 * and a material on several pages written once per page, each copy's LMGI_lightmap naming its page's
 * image. With one page every triangle is on page 0, every material its own, and the files keep the
 * names they had before pages. */
#ifndef LM_EXPORT_PAGES_H
#define LM_EXPORT_PAGES_H

#include <stddef.h>
#include <stdint.h>

#include "../charts/charts.h"
#include "../core/error.h"
#include "../scene/scene.h"

typedef struct {
    int pages, materials;  /* the atlas's page count; the scene's material count */
    int *first_page;       /* per material: the lowest page its triangles lie on (0 where none does) */
    int *index;            /* materials x pages: the glTF material of (material, page), -1 where unused */
    int copies;            /* glTF materials beyond the scene's own: materials .. materials + copies - 1 */
    int *copy;             /* 2 a copy: its material and page */
} lm_export_pages;

/* Per material, the pages its triangles lie on; the glTF index of each (material, page): the material's
 * own on its first page, a copy after the scene's materials on each other. */
lm_status lm_export_pages_make(const lm_scene *s, const lm_atlas *a, lm_export_pages *ep, lm_error *err);
void lm_export_pages_free(lm_export_pages *ep);
/* The page triangle t is exported on: its texels' page, or for a triangle without texels (mirror,
 * glass) its material's first page. */
int lm_export_tri_page(const lm_export_pages *ep, const lm_scene *s, const lm_atlas *a, uint32_t t);
/* "NAME_lightmap" + what (".exr", ".png", "_rgbd.png") for one page, "NAME_lightmap_pageP" + what for
 * page P of several. */
void lm_export_lightmap_file(char *out, size_t size, const char *name, const lm_export_pages *ep, int page,
                             const char *what);

#endif
