/* The lightmap's files, one a page (docs/levels.md, "Atlas"): a level of one page keeps the names it
 * always had (lightmap.exr), a level of several writes NAME_pageP for each page P (lightmap_page0.exr). */
#ifndef LM_CLI_PAGE_FILES_H
#define LM_CLI_PAGE_FILES_H

#include <lmgi.h>
#include <stddef.h>

/* BASE + EXT for one page, BASE_pageP + EXT for page P of several. */
void lm_cli_page_file(char *out, size_t size, const char *base, int pages, int page, const char *ext);
/* A page's size: the atlas's for one page. */
void lm_cli_page_size(const lmgi_info *in, int *width, int *height);
/* The lightmap of `kind` on page `page` into rgba (page-sized): lmgi_get_lightmap for one page,
 * lmgi_get_lightmap_page for several. */
lmgi_status lm_cli_get_page(lmgi_updater *u, const lmgi_info *in, lmgi_lightmap kind, int page, float *rgba,
                            size_t floats, lmgi_error *err);
/* "W x H" (the atlas) or "N pages of W x H": how the summaries size the lightmap. */
void lm_cli_atlas_size(char *out, size_t size, const lmgi_info *in);
/* "BASE.EXT" or "BASE_page0..P.EXT" (P the last page): how the "wrote" lines name a kind's files. */
void lm_cli_page_files(char *out, size_t size, const char *base, int pages, const char *ext);

#endif
