#include "page_files.h"

#include <stdio.h>

void lm_cli_page_file(char *out, size_t size, const char *base, int pages, int page, const char *ext)
{
    if (pages > 1)
        snprintf(out, size, "%s_page%d%s", base, page, ext);
    else
        snprintf(out, size, "%s%s", base, ext);
}

void lm_cli_page_size(const lmgi_info *in, int *width, int *height)
{
    *width = in->pages > 1 ? in->page_width : in->atlas_width;
    *height = in->pages > 1 ? in->page_height : in->atlas_height;
}

lmgi_status lm_cli_get_page(lmgi_updater *u, const lmgi_info *in, lmgi_lightmap kind, int page, float *rgba,
                            size_t floats, lmgi_error *err)
{
    return in->pages > 1 ? lmgi_get_lightmap_page(u, kind, page, rgba, floats, err)
                         : lmgi_get_lightmap(u, kind, rgba, floats, err);
}

void lm_cli_atlas_size(char *out, size_t size, const lmgi_info *in)
{
    if (in->pages > 1)
        snprintf(out, size, "%d pages of %d x %d", in->pages, in->page_width, in->page_height);
    else
        snprintf(out, size, "%d x %d", in->atlas_width, in->atlas_height);
}

void lm_cli_page_files(char *out, size_t size, const char *base, int pages, const char *ext)
{
    if (pages > 1)
        snprintf(out, size, "%s_page0..%d%s", base, pages - 1, ext);
    else
        snprintf(out, size, "%s%s", base, ext);
}
