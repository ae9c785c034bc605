/* lmgi-mpi: the lmgi command, with `bake` spread over the ranks of an MPI job (docs/farm.md).
 *
 * `mpirun -n N lmgi-mpi bake SCENE --out DIR` is a bake shared by N processes (lmgi_updater_desc's
 * photon_exchange and claim_pass): every rank traces 1/N of the photons and gets the others' by
 * MPI_Allgatherv, so each has the one-process photon map; rank 0 hands out the gather's passes as the ranks
 * finish them (a thread of its own answers the others' requests), so a faster rank gathers more; each rank's
 * part (the passes it took) goes to rank 0, which puts them together as `lmgi merge` does, into DIR. So the
 * lightmaps are the one-process bake's, to the bit, and DIR is written by rank 0 alone, at the end, as a
 * bake writes it (whole or not at all). A rank that fails says so, naming itself, and ends the job
 * (MPI_Abort); a rank that dies ends it too (mpirun's own rule). With one rank, and for every other
 * command, it is the plain lmgi (main.c, compiled again with main renamed lm_cli_main). */
#define _XOPEN_SOURCE 700 /* nftw */
#include <mpi.h>

#include <ftw.h>
#include <limits.h>
#include <lmgi_tools.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "../args.h"
#include "../bake_cmd.h"
#include "../merge_cmd.h"
#include "../options.h"
#include "../read_file.h"

int lm_cli_main(int argc, char **argv);

#define TAG_SIZE 1
#define TAG_BYTES 2
#define TAG_CLAIM 3
#define LEAVING -2      /* a claim request from a rank that takes no more passes */
#define CHUNK (1 << 30) /* bytes a message: MPI counts are ints */

/* What the ranks share while they bake. The claims travel on a communicator of their own, so that rank
 * 0's answering thread never meets the main threads' collectives. */
typedef struct {
    int rank, ranks;
    MPI_Comm claims;
    atomic_int next;    /* rank 0: the next pass to hand out */
    int done;           /* this rank was told no pass is left */
    int taken;          /* passes this rank gathers */
    int question, answer; /* ranks > 0: the claim under way (asking), its passes and rank 0's answer */
    MPI_Request asking;
    uint64_t received;  /* bytes of photon paths this rank received from the others */
    int balanced;       /* passes handed out as ranks finish them (MPI_THREAD_MULTIPLE); 0: dealt in turn */
} sharing;

/* lmgi_updater_desc.photon_exchange over MPI_COMM_WORLD: the byte counts by MPI_Allgather, then the
 * bytes by MPI_Allgatherv (a batch's paths are megabytes, far under MPI's int counts). */
static int exchange_photons(void *user, const void *mine, size_t size, size_t *sizes, void *all)
{
    sharing *sh = user;
    uint64_t own = size, *each = malloc(sizeof *each * (size_t)sh->ranks);
    int *counts = malloc(sizeof *counts * (size_t)sh->ranks), *at = malloc(sizeof *at * (size_t)sh->ranks);
    int ok = each && counts && at && MPI_Allgather(&own, 1, MPI_UINT64_T, each, 1, MPI_UINT64_T, MPI_COMM_WORLD) == MPI_SUCCESS;
    uint64_t total = 0;
    for (int r = 0; ok && r < sh->ranks; r++) {
        sizes[r] = (size_t)each[r];
        at[r] = (int)total, counts[r] = (int)each[r];
        total += each[r];
        ok = total <= INT_MAX;
    }
    if (ok && all)
        ok = MPI_Allgatherv(mine, (int)size, MPI_BYTE, all, counts, at, MPI_BYTE, MPI_COMM_WORLD) == MPI_SUCCESS;
    if (ok && all)
        sh->received += total - size;
    free(each);
    free(counts);
    free(at);
    return ok;
}

/* The next pass of `passes` from rank 0's counter, or -1 when none is left. */
static int hand_out(sharing *sh, int passes)
{
    int p = atomic_fetch_add(&sh->next, 1);
    return p < passes ? p : -1;
}

/* Asks rank 0 for a pass; the answer comes into sh->answer (sh->asking until it has). */
static void ask(sharing *sh, int passes)
{
    sh->question = passes;
    MPI_Request sent;
    MPI_Isend(&sh->question, 1, MPI_INT, 0, TAG_CLAIM, sh->claims, &sent);
    MPI_Request_free(&sent); /* a one-int message: it goes at once */
    MPI_Irecv(&sh->answer, 1, MPI_INT, 0, TAG_CLAIM, sh->claims, &sh->asking);
}

/* lmgi_updater_desc.claim_pass: rank 0 takes from its counter, the others ask rank 0, one pass ahead: the
 * question for the next pass goes out before this one is gathered, so its answer does not wait on rank
 * 0's answering thread (which the gather's own threads keep off the cores for milliseconds at a time). */
static int claim_pass(void *user, int passes)
{
    sharing *sh = user;
    int pass = -1;
    if (sh->rank == 0) {
        pass = hand_out(sh, passes);
    } else if (!sh->done) {
        if (sh->asking == MPI_REQUEST_NULL)
            ask(sh, passes);
        MPI_Wait(&sh->asking, MPI_STATUS_IGNORE);
        pass = sh->answer;
        if (pass >= 0)
            ask(sh, passes);
    }
    sh->done |= pass < 0;
    sh->taken += pass >= 0;
    return pass;
}

/* Rank 0's thread that answers the other ranks' claims until every one has been told no pass is left or
 * has left. It polls (every 0.2 ms) rather than waiting in MPI_Recv, whose busy wait would take a core
 * from the gather. */
static void *answer_claims(void *user)
{
    sharing *sh = user;
    for (int gone = 0; gone < sh->ranks - 1;) {
        int waiting = 0, asked = 0;
        MPI_Status st;
        MPI_Iprobe(MPI_ANY_SOURCE, TAG_CLAIM, sh->claims, &waiting, &st);
        if (!waiting) {
            nanosleep(&(struct timespec){0, 200000}, NULL);
            continue;
        }
        MPI_Recv(&asked, 1, MPI_INT, st.MPI_SOURCE, TAG_CLAIM, sh->claims, MPI_STATUS_IGNORE);
        if (asked == LEAVING) {
            gone++;
            continue;
        }
        int pass = hand_out(sh, asked);
        gone += pass < 0;
        MPI_Send(&pass, 1, MPI_INT, st.MPI_SOURCE, TAG_CLAIM, sh->claims);
    }
    return NULL;
}

/* What a rank did: its bake's stage times and the gather passes it took. */
typedef struct {
    lm_cli_bake_times t;
    int passes;
} rank_report;

/* Sends (rank > 0) or receives (from `peer`, on rank 0) a part: its rank's report and its size first
 * (size -1: the part could not be read), then its bytes. */
static void send_part(const rank_report *rp, const unsigned char *data, int64_t size)
{
    const lm_cli_bake_times *t = &rp->t;
    double times[5] = {t->seconds, t->ms_trace, t->ms_aim, t->ms_gather, rp->passes};
    MPI_Send(times, 5, MPI_DOUBLE, 0, TAG_SIZE, MPI_COMM_WORLD);
    MPI_Send(&size, 1, MPI_INT64_T, 0, TAG_SIZE, MPI_COMM_WORLD);
    for (int64_t at = 0; at < size; at += CHUNK)
        MPI_Send(data + at, (int)(size - at < CHUNK ? size - at : CHUNK), MPI_BYTE, 0, TAG_BYTES, MPI_COMM_WORLD);
}

static unsigned char *receive_part(int peer, rank_report *rp, int64_t *size)
{
    double times[5];
    MPI_Recv(times, 5, MPI_DOUBLE, peer, TAG_SIZE, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    *rp = (rank_report){{times[0], times[1], times[2], times[3]}, (int)times[4]};
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

/* Rank 0's table of the job's stages: each rank's bake (its share of the photon trace, its AIMs, its
 * gather and the passes it took, the whole), when its part reached rank 0, and the merge. */
static void print_stages(const rank_report *rp, const double *arrived, int ranks, double merge, uint64_t received,
                         int64_t part)
{
    printf("stages      rank  trace ms  AIMs ms  gather ms  passes  shard s  part at s\n");
    for (int r = 0; r < ranks; r++) {
        const lm_cli_bake_times *t = &rp[r].t;
        printf("            %4d %9.0f %8.0f %10.0f %7d %8.2f %10.2f\n", r, t->ms_trace, t->ms_aim, t->ms_gather,
               rp[r].passes, t->seconds, arrived[r]);
    }
    printf("            merge (photons, AIMs, parts joined, lightmaps written) %.2f s\n", merge);
    printf("traffic     photon paths %.1f MB into each rank; parts %.1f MB each into rank 0\n", (double)received / 1e6,
           (double)part / 1e6);
}

static int remove_entry(const char *path, const struct stat *st, int flag, struct FTW *ftw)
{
    (void)st, (void)flag, (void)ftw;
    return remove(path);
}

/* The whole bake over `ranks` ranks; returns the command's exit status (rank 0's counts). Rank 0 says
 * when each part has come, the job's progress. */
static int bake_over_ranks(const lm_cli_args *a, int rank, int ranks, int balanced)
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
    sharing sh = {.rank = rank, .ranks = ranks, .balanced = balanced, .asking = MPI_REQUEST_NULL};
    MPI_Comm_dup(MPI_COMM_WORLD, &sh.claims);
    atomic_init(&sh.next, 0);
    pthread_t answering;
    int rc = dir[0] ? 0 : 1;
    if (rc == 0 && rank == 0 && balanced && pthread_create(&answering, NULL, answer_claims, &sh) != 0) {
        fprintf(stderr, "lmgi: error: rank 0 cannot start the thread that hands out the gather's passes\n");
        rc = 1;
    }
    /* rank 0's progress is the whole job's where the passes are handed out: the pass it was last given */
    lm_cli_share share = {exchange_photons, balanced ? claim_pass : NULL, &sh, rank == 0 && !a->quiet};
    if (rc == 0)
        rc = lm_cli_bake_shared(&shard, &share, &mine_t);
    if (rc != 0) { /* the others cannot finish without this rank's photons or passes: end the job */
        if (rc == 130) /* SIGTERM: mpirun stops the others when a rank dies or the job is cancelled */
            fprintf(stderr, "lmgi: rank %d of %d was stopped (the job was cancelled, or another rank died: mpirun "
                    "names it); the MPI bake writes nothing into %s\n", rank, ranks, a->out_dir);
        else
            fprintf(stderr, "lmgi: error: rank %d of %d failed (its message above); the MPI bake ends and writes "
                    "nothing into %s\n", rank, ranks, a->out_dir);
        if (dir[0])
            nftw(dir, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
        MPI_Abort(MPI_COMM_WORLD, 1);
    }
    if (rank > 0 && balanced && !sh.done) { /* a bake with no pass to gather never asked */
        int leaving = LEAVING;
        MPI_Send(&leaving, 1, MPI_INT, 0, TAG_CLAIM, sh.claims);
    }
    if (rank == 0 && balanced)
        pthread_join(answering, NULL);
    MPI_Comm_free(&sh.claims);
    int status = 0;
    if (rank > 0) {
        size_t n = 0;
        char *mine = lm_cli_read_file(part, SIZE_MAX, &n);
        send_part(&(rank_report){mine_t, sh.taken}, (const unsigned char *)mine, mine ? (int64_t)n : -1);
        free(mine);
    } else {
        char (*paths)[4400] = calloc((size_t)ranks, sizeof *paths);
        const char **parts = calloc((size_t)ranks, sizeof *parts);
        rank_report *times = calloc((size_t)ranks, sizeof *times);
        double *arrived = calloc((size_t)ranks, sizeof *arrived);
        int failed = !paths || !parts || !times || !arrived;
        int64_t part_bytes = 0;
        for (int r = 0; r < ranks; r++) { /* rank 0's own part is merged where its shard wrote it */
            int64_t n = 0;
            rank_report t = {mine_t, sh.taken};
            unsigned char *data = r ? receive_part(r, &t, &n) : NULL;
            int have = !r || data;
            part_bytes = n > part_bytes ? n : part_bytes;
            if (times && arrived)
                times[r] = t, arrived[r] = MPI_Wtime() - started;
            if (have && !a->quiet)
                printf("bake: part %d of %d in (%.1f s)\n", r + 1, ranks, MPI_Wtime() - started), fflush(stdout);
            if (!have) {
                fprintf(stderr, "lmgi: error: rank %d's part %s\n", r,
                        n == -2 ? "could not be received (no memory)" : "could not be read (its message above)");
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
                print_stages(times, arrived, ranks, MPI_Wtime() - merging, sh.received, part_bytes);
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
    /* the thread that hands out passes calls MPI beside the main thread's collectives */
    int threads = MPI_THREAD_SINGLE;
    MPI_Init_thread(&argc, &argv, MPI_THREAD_MULTIPLE, &threads);
    int rank = 0, ranks = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    int rc;
    if (ranks > 1 && argc > 1 && !strcmp(argv[1], "bake")) {
        lm_cli_args a;
        rc = lm_cli_start(argc, argv, lm_cli_print_help, 1, &a);
        if (rc < 0 && rank == 0 && threads < MPI_THREAD_MULTIPLE)
            fprintf(stderr, "lmgi: warning: this MPI gives no MPI_THREAD_MULTIPLE: the gather's passes are dealt out "
                    "in turn, not handed out as the ranks finish them\n");
        rc = rc >= 0 ? rc : bake_over_ranks(&a, rank, ranks, threads >= MPI_THREAD_MULTIPLE);
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
