/* lmgi tradeoff's files (tradeoff_write.h). */
#include "tradeoff_write.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

void lm_tradeoff_scene_name(const char *path, char *name, size_t size)
{
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    size_t n = 0;
    for (const char *p = base; *p && *p != '.' && n + 1 < size; p++)
        name[n++] = (*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9') || *p == '-'
                        ? *p : '_';
    name[n] = '\0';
    if (n == 0)
        snprintf(name, size, "scene");
}

static float *copy_map(const float *m, size_t n)
{
    float *c = m ? malloc(sizeof *c * n) : NULL;
    if (c)
        memcpy(c, m, sizeof *c * n);
    return c;
}

void lm_tradeoff_row_copy(lm_tradeoff_row *dst, const lm_tradeoff_row *src)
{
    lm_tradeoff_setting keep = dst->setting;
    int is_default = dst->is_default;
    *dst = *src;
    dst->setting = keep;
    dst->is_default = is_default;
    dst->iim_map = copy_map(src->iim_map, (size_t)src->map_width * (size_t)src->map_height);
    dst->frame_map = copy_map(src->frame_map, (size_t)src->frame_width * (size_t)src->frame_height);
}

void lm_tradeoff_scene_free(lm_tradeoff_scene *s)
{
    for (int i = 0; i < s->play_count; i++)
        free(s->plays[i].frames);
    free(s->plays);
    s->plays = NULL;
    s->play_count = 0;
    for (int i = 0; i < s->count; i++) {
        free(s->rows[i].iim_map);
        free(s->rows[i].frame_map);
    }
    free(s->rows);
    s->rows = NULL;
    s->count = 0;
}

/* ---------- maps (.npy: numpy's own format, a fixed header then the raw little-endian floats) ---------- */

static int write_npy(const char *path, const float *v, int height, int width)
{
    char header[128];
    int len = snprintf(header, sizeof header, "{'descr': '<f4', 'fortran_order': False, 'shape': (%d, %d), }",
                       height, width);
    int total = 10 + len + 1, pad = (64 - total % 64) % 64; /* magic, version, length; aligned to 64 */
    FILE *f = fopen(path, "wbx");
    if (!f)
        return 0;
    unsigned short hl = (unsigned short)(len + pad + 1);
    unsigned char pre[10] = {0x93, 'N', 'U', 'M', 'P', 'Y', 1, 0, (unsigned char)(hl & 0xff), (unsigned char)(hl >> 8)};
    int ok = fwrite(pre, 1, 10, f) == 10 && fwrite(header, 1, (size_t)len, f) == (size_t)len;
    for (int i = 0; i < pad && ok; i++)
        ok = fputc(' ', f) != EOF;
    ok = ok && fputc('\n', f) != EOF;
    size_t n = (size_t)width * (size_t)height;
    ok = ok && fwrite(v, sizeof *v, n, f) == n; /* this code runs on little-endian machines (x86-64, arm64) */
    return (fclose(f) == 0) && ok;
}

/* The default, the fastest (the cheapest full solution) and the most accurate (the smallest IIM error)
 * of the settings that have lightmaps. -1 where none. */
static void pick_maps(const lm_tradeoff_scene *s, int pick[3])
{
    pick[0] = pick[1] = pick[2] = -1;
    for (int i = 0; i < s->count; i++) {
        const lm_tradeoff_row *r = &s->rows[i];
        if (!r->iim_map || !r->frame_map)
            continue;
        if (r->is_default && pick[0] < 0)
            pick[0] = i;
        if (pick[1] < 0 || r->ms_solution < s->rows[pick[1]].ms_solution)
            pick[1] = i;
        if (pick[2] < 0 || r->iim.rmse < s->rows[pick[2]].iim.rmse)
            pick[2] = i;
    }
}

static const char *const WHICH[3] = {"default", "fastest", "most_accurate"};

static int write_maps(const char *dir, const lm_tradeoff_scene *s, const int pick[3])
{
    char path[PATH_MAX];
    for (int w = 0; w < 3; w++) {
        if (pick[w] < 0)
            continue;
        const lm_tradeoff_row *r = &s->rows[pick[w]];
        snprintf(path, sizeof path, "%s/map_%s_%s_iim.npy", dir, s->name, WHICH[w]);
        if (!write_npy(path, r->iim_map, r->map_height, r->map_width))
            return fprintf(stderr, "lmgi: error: cannot write %s: %s\n", path, strerror(errno)), 0;
        snprintf(path, sizeof path, "%s/map_%s_%s_frame.npy", dir, s->name, WHICH[w]);
        if (!write_npy(path, r->frame_map, r->frame_height, r->frame_width))
            return fprintf(stderr, "lmgi: error: cannot write %s: %s\n", path, strerror(errno)), 0;
    }
    return 1;
}

/* ---------- CSV and JSON ---------- */

static void json_string(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; s++) {
        if (*s == '"' || *s == '\\')
            fprintf(f, "\\%c", *s);
        else if ((unsigned char)*s < 0x20)
            fprintf(f, "\\u%04x", (unsigned char)*s);
        else
            fputc(*s, f);
    }
    fputc('"', f);
}

/* A number, or null (JSON) / empty (CSV) for NaN. */
static void num(FILE *f, double v, int json)
{
    if (isfinite(v))
        fprintf(f, "%.6g", v);
    else if (json)
        fputs("null", f);
}

static const char *const UPDATE_PARTS[8] = {"update", "update_photons", "update_gather", "update_direct",
                                            "update_caustics", "update_reflections", "update_composite",
                                            "update_blend"};

static void csv_row(FILE *f, const lm_tradeoff_scene *s, const lm_tradeoff_row *r)
{
    fprintf(f, "%s,%s,\"%s\",", s->name, r->setting.knob, r->setting.value);
    num(f, r->setting.x, 0);
    fprintf(f, ",%d,%d,%u,%d,", r->is_default, r->setting.target_texels, r->photons, r->coverage);
    const double ms[4] = {r->ms_solution, r->ms_trace, r->ms_aim, r->ms_gather};
    for (int k = 0; k < 4; k++)
        num(f, ms[k], 0), fputc(',', f);
    for (int k = 0; k < 8; k++)
        num(f, r->ms_update[k], 0), fputc(',', f);
    const lm_tradeoff_error *e[3] = {&r->aim, &r->iim, &r->frame};
    for (int k = 0; k < 3; k++) {
        num(f, e[k]->rmse, 0), fputc(',', f);
        num(f, e[k]->p99, 0), fputc(',', f);
        num(f, e[k]->worst, 0), fputc(',', f);
    }
    num(f, r->frame_bias, 0);
    for (int k = 0; k < 3; k++)
        fputc(',', f), num(f, r->frame_ratio[k], 0);
    fputc(',', f), num(f, r->frame_surface_rms, 0);
    fputc(',', f), num(f, r->frame_surface_worst, 0);
    fputc(',', f), num(f, r->caustic.rmse, 0);
    fputc(',', f), num(f, r->caustic.p99, 0);
    fputc(',', f), num(f, r->caustic.worst, 0);
    for (int k = 0; k < 3; k++)
        fputc(',', f), num(f, r->caustic_ratio[k], 0);
    fputc('\n', f);
}

static int write_csv(const char *path, const lm_tradeoff_run *run)
{
    FILE *f = fopen(path, "wx");
    if (!f)
        return 0;
    fprintf(f, "scene,knob,value,x,default,atlas_texels,photons,coverage,solution_ms,trace_ms,aim_ms,gather_ms");
    for (int k = 0; k < 8; k++)
        fprintf(f, ",%s_ms", UPDATE_PARTS[k]);
    fprintf(f, ",aim_rmse,aim_p99,aim_worst,iim_rmse,iim_p99,iim_worst,frame_rmse,frame_p99,frame_worst,"
               "frame_bias,frame_r,frame_g,frame_b,frame_surface_rms,frame_surface_worst,caustic_rmse,caustic_p99,"
               "caustic_worst,caustic_r,caustic_g,caustic_b\n");
    for (int i = 0; i < run->count; i++)
        for (int j = 0; j < run->scenes[i].count; j++)
            csv_row(f, &run->scenes[i], &run->scenes[i].rows[j]);
    return fclose(f) == 0;
}

static void json_error(FILE *f, const char *name, const lm_tradeoff_error *e)
{
    fprintf(f, ", \"%s\": {\"rmse\": ", name);
    num(f, e->rmse, 1);
    fprintf(f, ", \"p99\": ");
    num(f, e->p99, 1);
    fprintf(f, ", \"worst\": ");
    num(f, e->worst, 1);
    fprintf(f, ", \"count\": %u}", e->count);
}

static void json_row(FILE *f, const lm_tradeoff_row *r)
{
    fprintf(f, "{\"knob\": ");
    json_string(f, r->setting.knob);
    fprintf(f, ", \"label\": ");
    json_string(f, r->setting.label);
    fprintf(f, ", \"value\": ");
    json_string(f, r->setting.value);
    fprintf(f, ", \"x\": ");
    num(f, r->setting.x, 1);
    fprintf(f, ", \"default\": %s, \"atlas_texels\": %d, \"photons\": %u, \"coverage\": %d, \"photon_radius\": %.6g, "
            "\"ms\": {\"solution\": %.4f, \"trace\": %.4f, \"aim\": %.4f, \"gather\": %.4f",
            r->is_default ? "true" : "false", r->setting.target_texels, r->photons, r->coverage,
            (double)r->photon_radius, r->ms_solution, r->ms_trace, r->ms_aim, r->ms_gather);
    for (int k = 0; k < 8; k++)
        fprintf(f, ", \"%s\": %.4f", UPDATE_PARTS[k], r->ms_update[k]);
    fprintf(f, "}");
    json_error(f, "aim", &r->aim);
    json_error(f, "iim", &r->iim);
    json_error(f, "frame", &r->frame);
    json_error(f, "caustic", &r->caustic);
    fprintf(f, ", \"caustic_ratio\": [");
    for (int k = 0; k < 3; k++)
        fputs(k ? ", " : "", f), num(f, r->caustic_ratio[k], 1);
    fprintf(f, "], \"frame_bias\": ");
    num(f, r->frame_bias, 1);
    fprintf(f, ", \"frame_surface_rms\": ");
    num(f, r->frame_surface_rms, 1);
    fprintf(f, ", \"frame_surface_worst\": ");
    num(f, r->frame_surface_worst, 1);
    fprintf(f, ", \"frame_ratio\": [%.6g, %.6g, %.6g], \"reference_rel_se\": %.6g}", r->frame_ratio[0],
            r->frame_ratio[1], r->frame_ratio[2], r->reference_rel_se);
}

/* ---------- update lag ---------- */

typedef struct {
    char what[128];
    int frame, frames_to[2], frame_to[2]; /* frame_to: by the frame's error (-1 also when not measured) */
    double error, ms_to[2], frame_error, frame_end, frame_ms[2]; /* frame_*: NAN when not measured */
} edit_lag;

/* Edit i's lag in play p, by the worst surface's distance and (--frame-lag) by the frame's error against
 * the reference, that error at the edit and at the end of its span; 0 when a later edit shares its frame
 * (that one reports). */
static int lag_of(const lm_edit_script *s, const lm_tradeoff_play *p, int i, edit_lag *l)
{
    int from, to;
    if (!lm_edit_span(s, i, &from, &to))
        return 0;
    lm_edit_describe(s->edits[i].v, l->what, sizeof l->what);
    l->frame = from;
    l->error = p->frames[from].worst_surface;
    lm_edit_lag(p->frames, from, to, 0.05, LM_LAG_WORST_SURFACE, &l->frames_to[0], &l->ms_to[0]);
    lm_edit_lag(p->frames, from, to, 0.02, LM_LAG_WORST_SURFACE, &l->frames_to[1], &l->ms_to[1]);
    lm_edit_lag(p->frames, from, to, 0.05, LM_LAG_FRAME, &l->frame_to[0], &l->frame_ms[0]);
    lm_edit_lag(p->frames, from, to, 0.02, LM_LAG_FRAME, &l->frame_to[1], &l->frame_ms[1]);
    l->frame_error = p->frames[from].frame_error;
    l->frame_end = p->frames[to - 1].frame_error;
    if (!p->frame_lag)
        l->frame_ms[0] = l->frame_ms[1] = NAN;
    return 1;
}

static int write_lag_csv(const char *path, const lm_tradeoff_run *run)
{
    FILE *f = fopen(path, "wx");
    if (!f)
        return 0;
    fprintf(f, "scene,knob,value,default,edit,frame,error,frames_to_5,ms_to_5,frames_to_2,ms_to_2,frame_error,"
            "frame_to_5,frame_ms_to_5,frame_to_2,frame_ms_to_2,frame_end\n");
    for (int i = 0; i < run->count; i++) {
        const lm_tradeoff_scene *s = &run->scenes[i];
        for (int p = 0; p < s->play_count; p++)
            for (int e = 0; s->plays[p].frames && e < s->script->edit_count; e++) {
                edit_lag l;
                if (lag_of(s->script, &s->plays[p], e, &l)) {
                    fprintf(f, "%s,%s,%d,%d,\"%s\",%d,%.5f,%d,%.2f,%d,%.2f,", s->name, s->plays[p].knob,
                            s->plays[p].value, s->plays[p].is_default, l.what, l.frame, l.error, l.frames_to[0],
                            l.ms_to[0], l.frames_to[1], l.ms_to[1]);
                    num(f, l.frame_error, 0); /* the frame's columns empty where it was not checked */
                    fprintf(f, ",%d,", l.frame_to[0]);
                    num(f, l.frame_ms[0], 0);
                    fprintf(f, ",%d,", l.frame_to[1]);
                    num(f, l.frame_ms[1], 0);
                    fputc(',', f);
                    num(f, l.frame_end, 0);
                    fputc('\n', f);
                }
            }
    }
    return fclose(f) == 0;
}

static void json_plays(FILE *f, const lm_tradeoff_scene *s)
{
    fprintf(f, ",\n   \"script\": ");
    json_string(f, s->script->path);
    fprintf(f, ", \"script_frames\": %d, \"plays\": [\n", s->script->frames);
    for (int p = 0; p < s->play_count; p++) {
        const lm_tradeoff_play *pl = &s->plays[p];
        fprintf(f, "    {\"knob\": \"%s\", \"value\": %d, \"default\": %s, \"frames\": [", pl->knob, pl->value,
                pl->is_default ? "true" : "false");
        for (int k = 0; pl->frames && k < s->script->frames; k++) {
            fprintf(f, "%s[%.5f, %.3f, %.5f, ", k ? ", " : "", pl->frames[k].worst_surface, pl->frames[k].ms_total,
                    pl->frames[k].error);
            num(f, pl->frames[k].frame_error, 1);
            fprintf(f, "]");
        }
        fprintf(f, "], \"edits\": [");
        int first = 1;
        for (int e = 0; pl->frames && e < s->script->edit_count; e++) {
            edit_lag l;
            if (!lag_of(s->script, pl, e, &l))
                continue;
            fprintf(f, "%s{\"edit\": ", first ? "" : ", ");
            json_string(f, l.what);
            fprintf(f, ", \"frame\": %d, \"error\": %.5f, \"frames_to_5\": %d, \"ms_to_5\": %.2f, "
                    "\"frames_to_2\": %d, \"ms_to_2\": %.2f, \"frame_to_5\": %d, \"frame_to_2\": %d, \"frame_ms_to_5\": ",
                    l.frame, l.error, l.frames_to[0], l.ms_to[0], l.frames_to[1], l.ms_to[1], l.frame_to[0],
                    l.frame_to[1]);
            num(f, l.frame_ms[0], 1);
            fprintf(f, ", \"frame_ms_to_2\": ");
            num(f, l.frame_ms[1], 1);
            fprintf(f, ", \"frame_error\": ");
            num(f, l.frame_error, 1);
            fprintf(f, ", \"frame_end\": ");
            num(f, l.frame_end, 1);
            fprintf(f, "}");
            first = 0;
        }
        fprintf(f, "]}%s\n", p + 1 < s->play_count ? "," : "");
    }
    fprintf(f, "   ]");
}

static int write_json(const char *path, const lm_tradeoff_run *run, int (*picks)[3])
{
    FILE *f = fopen(path, "wx");
    if (!f)
        return 0;
    fprintf(f, "{\"quick\": %s, \"repeats\": %d, \"reference_target_error\": %.4g, \"scenes\": [\n",
            run->quick ? "true" : "false", run->repeats, (double)run->target_error);
    for (int i = 0; i < run->count; i++) {
        const lm_tradeoff_scene *s = &run->scenes[i];
        fprintf(f, "  {\"name\": ");
        json_string(f, s->name);
        fprintf(f, ", \"path\": ");
        json_string(f, s->path);
        fprintf(f, ", \"reference_texels_seconds\": %.3f, \"reference_texels_rel_se\": %.4g, \"maps\": {",
                s->reference_texels_seconds, s->reference_texels_rel_se);
        int first = 1;
        for (int w = 0; w < 3; w++) {
            if (picks[i][w] < 0)
                continue;
            const lm_tradeoff_row *r = &s->rows[picks[i][w]];
            fprintf(f, "%s\"%s\": {\"row\": %d, \"iim\": \"map_%s_%s_iim.npy\", \"frame\": \"map_%s_%s_frame.npy\"}",
                    first ? "" : ", ", WHICH[w], picks[i][w], s->name, WHICH[w], s->name, WHICH[w]);
            (void)r;
            first = 0;
        }
        fprintf(f, "},\n   \"rows\": [\n");
        for (int j = 0; j < s->count; j++) {
            fprintf(f, "    ");
            json_row(f, &s->rows[j]);
            fprintf(f, "%s\n", j + 1 < s->count ? "," : "");
        }
        fprintf(f, "  ]");
        if (s->script)
            json_plays(f, s);
        fprintf(f, "}%s\n", i + 1 < run->count ? "," : "");
    }
    fprintf(f, "]}\n");
    return fclose(f) == 0;
}

int lm_tradeoff_write(const char *dir, const lm_tradeoff_run *run)
{
    int (*picks)[3] = calloc((size_t)(run->count ? run->count : 1), sizeof *picks);
    if (!picks)
        return fprintf(stderr, "lmgi: error: no memory\n"), 0;
    int ok = 1;
    for (int i = 0; i < run->count && ok; i++) {
        pick_maps(&run->scenes[i], picks[i]);
        ok = write_maps(dir, &run->scenes[i], picks[i]);
    }
    char path[PATH_MAX];
    snprintf(path, sizeof path, "%s/tradeoff.csv", dir);
    if (ok && !write_csv(path, run))
        ok = 0, fprintf(stderr, "lmgi: error: cannot write %s: %s\n", path, strerror(errno));
    snprintf(path, sizeof path, "%s/lag.csv", dir);
    if (ok && !write_lag_csv(path, run))
        ok = 0, fprintf(stderr, "lmgi: error: cannot write %s: %s\n", path, strerror(errno));
    snprintf(path, sizeof path, "%s/tradeoff.json", dir);
    if (ok && !write_json(path, run, picks))
        ok = 0, fprintf(stderr, "lmgi: error: cannot write %s: %s\n", path, strerror(errno));
    free(picks);
    return ok;
}

/* ---------- the report ---------- */

/* tools/tradeoff_report.py beside the executable: ../tools (build/lmgi), ../../tools (a build tree one
 * level deeper: build/asan/lmgi, make test-asan's) or ../share/lmgi (an install). */
static int find_script(char *out, size_t size)
{
    char exe[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n <= 0)
        return 0;
    exe[n] = '\0';
    char *slash = strrchr(exe, '/');
    if (!slash)
        return 0;
    *slash = '\0';
    static const char *const rel[] = {"../tools/tradeoff_report.py", "../../tools/tradeoff_report.py",
                                      "../share/lmgi/tradeoff_report.py"};
    for (int i = 0; i < 3; i++) {
        snprintf(out, size, "%s/%s", exe, rel[i]);
        if (access(out, R_OK) == 0)
            return 1;
    }
    return 0;
}

int lm_tradeoff_report(const char *dir, const char *shown)
{
    char script[PATH_MAX + 64];
    if (!find_script(script, sizeof script)) {
        fprintf(stderr, "lmgi: error: tools/tradeoff_report.py not found beside the lmgi executable: "
                        "%s/tradeoff.csv and .json are written; run python3 tools/tradeoff_report.py %s for the "
                        "report\n", shown, shown);
        return 0;
    }
    fflush(NULL);
    pid_t pid = fork();
    if (pid == 0) {
        /* Debian's python3 first: make deps installs matplotlib for it, whatever python3 PATH finds */
        const char *py = access("/usr/bin/python3", X_OK) == 0 ? "/usr/bin/python3" : "python3";
        execlp(py, py, script, dir, "-q", (char *)NULL); /* it would name the folder it writes in, not `shown` */
        fprintf(stderr, "lmgi: error: cannot run python3: %s\n", strerror(errno));
        _exit(127);
    }
    int status = 0;
    if (pid < 0 || waitpid(pid, &status, 0) < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        fprintf(stderr, "lmgi: error: the report (python3 %s %s) failed: it needs python3 and matplotlib "
                        "(make deps installs them); tradeoff.csv and .json are written\n", script, shown);
        return 0;
    }
    return 1;
}
