#include "out_dir.h"

#include <stdio.h>

int lm_cli_claim_out_dir(const lm_cli_args *a, const char *const *own)
{
    lmgi_error err;
    if (lmgi_claim_output_dir(a->out_dir, a->force, own, &err) == LMGI_OK)
        return 1;
    fprintf(stderr, "lmgi: error: %s\n", err.message);
    return 0;
}

lmgi_status lm_cli_write_image(const char *dir, const char *name, int width, int height, int channels,
                               const float *pixels, const lmgi_image_desc *desc, lmgi_error *err)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    return lmgi_write_image(path, width, height, channels, pixels, desc, err);
}
