/* FNV-1a, 64 bits (Fowler, Noll, Vo): the hash the reference's cache keys and checksums, the frame loop and
 * the caustic photons compare states with. Not for anything an adversary chooses. */
#ifndef LM_HASH_H
#define LM_HASH_H

#include <stddef.h>
#include <stdint.h>

#define LM_HASH_SEED 0xcbf29ce484222325ull /* FNV-1a's offset basis */

/* h extended by n bytes at p. */
static inline uint64_t lm_hash_bytes(uint64_t h, const void *p, size_t n)
{
    const unsigned char *b = p;
    for (size_t i = 0; i < n; i++)
        h = (h ^ b[i]) * 0x100000001b3ull; /* FNV-1a's prime */
    return h;
}

#endif
