/* The k greatest of a stream of (key, id) pairs, kept as they come in a bounded min-heap of the caller's k
 * slots: O(n log k) for n offers, no allocation. Ranked by key, greatest first, ties by the smaller id, so
 * the choice is the same on every run whatever the order of the offers (the texels an update picks ahead,
 * photonmap/texel_change.h, and those whose ray estimates it brings up to date, update/ray_estimate.h).
 * The heap's order is not the ranking: sort it with lm_ranked_order where that matters. Not thread-safe
 * (a heap is its caller's). */
#ifndef LM_TOP_K_H
#define LM_TOP_K_H

#include <stdint.h>

typedef struct {
    double key;
    uint32_t id;
} lm_ranked;

/* < 0 when a ranks before b (a greater key, or the same and a smaller id), > 0 after it, 0 the same pair: as
 * a qsort comparator, the greatest first. */
static inline int lm_ranked_order(const void *pa, const void *pb)
{
    const lm_ranked *a = (const lm_ranked *)pa, *b = (const lm_ranked *)pb;
    if (a->key != b->key)
        return a->key > b->key ? -1 : 1;
    return a->id < b->id ? -1 : a->id > b->id;
}

/* Offers c to the heap h[0 .. *n) that keeps the k (> 0) greatest offered so far, the least of them at h[0]. */
static inline void lm_top_k_offer(lm_ranked *h, uint32_t *n, uint32_t k, lm_ranked c)
{
    if (*n == k && lm_ranked_order(&c, &h[0]) >= 0)
        return;
    uint32_t i;
    if (*n < k) { /* sift up from the end */
        i = (*n)++;
        while (i > 0 && lm_ranked_order(&h[(i - 1) / 2], &c) < 0)
            h[i] = h[(i - 1) / 2], i = (i - 1) / 2;
    } else { /* replace the least and sift down */
        i = 0;
        for (;;) {
            uint32_t l = 2 * i + 1, r = l + 1, m = i;
            const lm_ranked *least = &c;
            if (l < *n && lm_ranked_order(&h[l], least) > 0)
                m = l, least = &h[l];
            if (r < *n && lm_ranked_order(&h[r], least) > 0)
                m = r;
            if (m == i)
                break;
            h[i] = h[m], i = m;
        }
    }
    h[i] = c;
}

#endif
