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
