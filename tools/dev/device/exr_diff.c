/* exr_diff A.exr B.exr: how far A is from B (B the reference), for comparing the same lmgi command's
 * outputs on two GL implementations (tools/dev/device_egl_check.sh). Prints one line:
 *   size, rel_l1 = sum|A-B| / sum|B| over RGB, mean_rel = mean over pixels of |lumA-lumB| / lumB where
 *   lumB > 1e-3 x mean lumB (and, where alpha differs, the count), max_rel, and the fraction of those
 *   pixels more than 5% apart (over5%: how many of how many).
 * Build: cc -O2 -o exr_diff tools/dev/device/exr_diff.c -ltinyexr -lm */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <tinyexr.h>

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: exr_diff A.exr B.exr\n");
        return 2;
    }
    float *a = NULL, *b = NULL;
    int wa, ha, wb, hb;
    const char *msg = NULL;
    if (LoadEXR(&a, &wa, &ha, argv[1], &msg) != 0 || LoadEXR(&b, &wb, &hb, argv[2], &msg) != 0) {
        printf("exr_diff: cannot read %s: %s\n", a ? argv[2] : argv[1], msg ? msg : "?");
        return 1;
    }
    if (wa != wb || ha != hb) {
        printf("size differs: %dx%d vs %dx%d\n", wa, ha, wb, hb);
        return 1;
    }
    size_t n = (size_t)wa * ha;
    double sum_d = 0, sum_b = 0, mean_lb = 0;
    size_t alpha_diff = 0;
    for (size_t i = 0; i < n; i++) {
        for (int c = 0; c < 3; c++) {
            sum_d += fabs((double)a[4 * i + c] - b[4 * i + c]);
            sum_b += fabs((double)b[4 * i + c]);
        }
        alpha_diff += (a[4 * i + 3] > 0.5f) != (b[4 * i + 3] > 0.5f);
        mean_lb += 0.2126 * b[4 * i] + 0.7152 * b[4 * i + 1] + 0.0722 * b[4 * i + 2];
    }
    mean_lb /= (double)n;
    double sum_rel = 0, max_rel = 0;
    size_t used = 0, over5 = 0;
    for (size_t i = 0; i < n; i++) {
        double la = 0.2126 * a[4 * i] + 0.7152 * a[4 * i + 1] + 0.0722 * a[4 * i + 2];
        double lb = 0.2126 * b[4 * i] + 0.7152 * b[4 * i + 1] + 0.0722 * b[4 * i + 2];
        if (!(lb > 1e-3 * mean_lb))
            continue;
        double r = fabs(la - lb) / lb;
        sum_rel += r;
        max_rel = r > max_rel ? r : max_rel;
        over5 += r > 0.05;
        used++;
    }
    printf("%dx%d rel_l1 %.5f mean_rel %.5f max_rel %.3f over5%% %zu of %zu px, alpha_differs %zu\n", wa, ha,
           sum_b > 0 ? sum_d / sum_b : 0.0, used ? sum_rel / used : 0.0, max_rel, over5, used, alpha_diff);
    free(a);
    free(b);
    return 0;
}
