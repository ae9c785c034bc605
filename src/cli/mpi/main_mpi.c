/* lmgi-mpi: the lmgi command, with `bake` spread over the ranks of an MPI job (docs/farm.md).
 *
 * `mpirun -n N lmgi-mpi bake SCENE --out DIR` is a bake in N shards (docs/levels.md, "A bake in shards")
 * whose parts travel by MPI instead of files: rank r bakes shard r + 1 of N into a folder of its own under
 * $TMPDIR, sends its part to rank 0, and rank 0 puts the parts together as `lmgi merge` does, into DIR.
 * So the lightmaps are the one-process bake's, to the bit, and DIR is written by rank 0 alone, at the end,
 * as a bake writes it (whole or not at all). A rank whose shard fails tells rank 0, which names it and
 * writes nothing; a rank that dies ends the job (mpirun's own rule). With one rank, and for every other
 * command, it is the plain lmgi (main.c, compiled again with main renamed lm_cli_main). */
#define _XOPEN_SOURCE 700 /* nftw */
#include <mpi.h>

#include <ftw.h>
#include <lmgi.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../args.h"
#include "../bake_cmd.h"
#include "../options.h"

int lm_cli_main(int argc, char **argv);

#define TAG_SIZE 1
#define TAG_BYTES 2
#define CHUNK (1 << 30) /* bytes a message: MPI counts are ints */

static unsigned char *read_all(const char *path, int64_t *size)
{
    FILE *f = fopen(path, "rb");
    unsigned char *data = NULL;
    long n = -1;
    if (f && fseek(f, 0, SEEK_END) == 0 && (n = ftell(f)) >= 0 && fseek(f, 0, SEEK_SET) == 0 &&
        (data = malloc((size_t)n + 1)) != NULL && fread(data, 1, (size_t)n, f) != (size_t)n) {
        free(data);
        data = NULL;
    }
    if (f)
        fclose(f);
    *size = data ? (int64_t)n : -1;
    return data;
}

/* Sends (rank > 0) or receives (from `peer`, on rank 0) a part: its shard's stage times and its size
 * first (size -1: the shard failed), then its bytes. */
static void send_part(const lm_cli_bake_times *t, const unsigned char *data, int64_t size)
{
    double times[4] = {t->seconds, t->ms_trace, t->ms_aim, t->ms_gather};
    MPI_Send(times, 4, MPI_DOUBLE, 0, TAG_SIZE, MPI_COMM_WORLD);
    MPI_Send(&size, 1, MPI_INT64_T, 0, TAG_SIZE, MPI_COMM_WORLD);
    for (int64_t at = 0; at < size; at += CHUNK)
        MPI_Send(data + at, (int)(size - at < CHUNK ? size - at : CHUNK), MPI_BYTE, 0, TAG_BYTES, MPI_COMM_WORLD);
}

static unsigned char *receive_part(int peer, lm_cli_bake_times *t, int64_t *size)
{
    double times[4];
    MPI_Recv(times, 4, MPI_DOUBLE, peer, TAG_SIZE, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    *t = (lm_cli_bake_times){times[0], times[1], times[2], times[3]};
    MPI_Recv(size, 1, MPI_INT64_T, peer, TAG_SIZE, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    if (*size < 0)
        return NULL;
    unsigned char *data = malloc((size_t)*size + 1);
    for (int64_t at = 0; at < *size; at += CHUNK) { /* received even without memory, so the sender ends */
        int n = (int)(*size - at < CHUNK ? *size - at : CHUNK);
        unsigned char *sink = data ? data + at : malloc((size_t)n);
        MPI_Recv(sink, n, MPI_BYTE, peer, TAG_BYTES, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        if (!data)
            free(sink);
    }
    if (!data)
        *size = -2;
    return data;
}

/* Rank 0's table of the job's stages: each rank's shard (its photon trace, AIMs and gather, and the whole
 * shard), when its part reached rank 0, and the merge. */
static void print_stages(const lm_cli_bake_times *t, const double *arrived, int ranks, double merge)
{
    printf("stages      rank  trace ms  AIMs ms  gather ms  shard s  part at s\n");
    for (int r = 0; r < ranks; r++)
        printf("            %4d %9.0f %8.0f %10.0f %8.2f %10.2f\n", r, t[r].ms_trace, t[r].ms_aim, t[r].ms_gather,
               t[r].seconds, arrived[r]);
    printf("            merge (photons, AIMs, parts joined, lightmaps written) %.2f s\n", merge);
}

static int remove_entry(const char *path, const struct stat *st, int flag, struct FTW *ftw)
{
    (void)st, (void)flag, (void)ftw;
    return remove(path);
}

/* The whole bake over `ranks` ranks; returns the command's exit status (rank 0's counts). Rank 0 says
 * when each part has come, the job's progress. */
static int bake_over_ranks(const lm_cli_args *a, int rank, int ranks)
{
    if (a->file_count != 1 || !a->out_dir || a->shards || a->resume) {
        if (rank == 0)
            fprintf(stderr, "lmgi: an MPI bake needs one scene file and --out DIR, without --shard or --resume\n");
        return 2;
    }
    const char *tmp = getenv("TMPDIR");
    char dir[4096];
    snprintf(dir, sizeof dir, "%s/lmgi-rank%d-XXXXXX", tmp && *tmp ? tmp : "/tmp", rank);
    if (!mkdtemp(dir)) {
        fprintf(stderr, "lmgi: error: rank %d: cannot make a folder under %s\n", rank, tmp && *tmp ? tmp : "/tmp");
        dir[0] = '\0';
    }
    char part_dir[4200], part[4300];
    snprintf(part_dir, sizeof part_dir, "%s/part", dir);
    snprintf(part, sizeof part, "%s/part.checkpoint", part_dir);
    lm_cli_args shard = *a;
    shard.shard = rank + 1;
    shard.shards = ranks;
    shard.out_dir = part_dir;
    shard.quiet = 1; /* its temporary part is nobody's business; rank 0 says how the job goes */
    shard.gltf = shard.accuracy = shard.half = 0;
    double started = MPI_Wtime();
    lm_cli_bake_times mine_t = {0};
    int rc = dir[0] ? lm_cli_bake_timed(&shard, &mine_t) : 1;
    int status = 0;
    if (rank > 0) {
        int64_t size = -1;
        unsigned char *mine = rc == 0 ? read_all(part, &size) : NULL;
        send_part(&mine_t, mine, size);
        free(mine);
    } else if (rc != 0) { /* the others' parts are of no use now: end the job */
        fprintf(stderr, "lmgi: error: rank 0's shard 1 of %d failed (or the job was stopped: a rank died, or "
                "mpirun was cancelled); the MPI bake wrote nothing into %s\n", ranks, a->out_dir);
        if (dir[0])
            nftw(dir, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
        MPI_Abort(MPI_COMM_WORLD, 1);
    } else {
        char (*paths)[4400] = calloc((size_t)ranks, sizeof *paths);
        const char **parts = calloc((size_t)ranks, sizeof *parts);
        lm_cli_bake_times *times = calloc((size_t)ranks, sizeof *times);
        double *arrived = calloc((size_t)ranks, sizeof *arrived);
        int failed = !paths || !parts || !times || !arrived;
        for (int r = 0; r < ranks; r++) { /* rank 0's own part is merged where its shard wrote it */
            int64_t n = 0;
            lm_cli_bake_times t = mine_t;
            unsigned char *data = r ? receive_part(r, &t, &n) : NULL;
            int have = !r || data;
            if (times && arrived)
                times[r] = t, arrived[r] = MPI_Wtime() - started;
            if (have && !a->quiet)
                printf("bake: part %d of %d in (%.1f s)\n", r + 1, ranks, MPI_Wtime() - started), fflush(stdout);
            if (!have) {
                fprintf(stderr, "lmgi: error: rank %d's shard %d of %d %s\n", r, r + 1, ranks,
                        n == -2 ? "could not be received (no memory)" : "failed (its message above)");
                failed = 1;
            }
            if (have && paths && parts) {
                if (r)
                    snprintf(paths[r], sizeof paths[r], "%s/rank%d.checkpoint", dir, r);
                else
                    snprintf(paths[r], sizeof paths[r], "%s", part);
                parts[r] = paths[r];
                lmgi_error e;
                if (r && lmgi_write_file(paths[r], data, (size_t)n, &e) != LMGI_OK) {
                    fprintf(stderr, "lmgi: error: %s\n", e.message);
                    failed = 1;
                }
            }
            free(data);
        }
        if (!failed) {
            lm_cli_args merge = *a;
            merge.file_count = 1 + ranks;
            for (int r = 0; r < ranks; r++)
                merge.files[1 + r] = parts[r];
            double merging = MPI_Wtime();
            status = lm_cli_merge(&merge);
            if (status == 0 && !a->quiet)
                print_stages(times, arrived, ranks, MPI_Wtime() - merging);
        } else {
            fprintf(stderr, "lmgi: the MPI bake wrote nothing into %s\n", a->out_dir);
            status = 1;
        }
        free(paths);
        free(parts);
        free(times);
        free(arrived);
    }
    if (dir[0])
        nftw(dir, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
    return rank == 0 ? status : rc;
}

int main(int argc, char **argv)
{
    MPI_Init(&argc, &argv);
    int rank = 0, ranks = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    int rc;
    if (ranks > 1 && argc > 1 && !strcmp(argv[1], "bake")) {
        lm_cli_args a;
        rc = lm_cli_start(argc, argv, lm_cli_print_help, 1, &a);
        rc = rc >= 0 ? rc : bake_over_ranks(&a, rank, ranks);
    } else if (ranks > 1) {
        if (rank == 0)
            fprintf(stderr, "lmgi: only bake runs over several MPI ranks; run other commands with one\n");
        rc = 2;
    } else {
        rc = lm_cli_main(argc, argv);
    }
    MPI_Finalize();
    return rc;
}
