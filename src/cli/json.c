#include "json.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_DEPTH 64

typedef struct {
    const char *s, *end;
    char *err;
    size_t err_size;
    int failed;
} parser;

static int fail(parser *p, const char *what)
{
    if (!p->failed) /* the first problem is the one to report; json_parse adds where */
        snprintf(p->err, p->err_size, "%s", what);
    p->failed = 1;
    return 0;
}

static void skip_space(parser *p)
{
    while (p->s < p->end && (*p->s == ' ' || *p->s == '\t' || *p->s == '\n' || *p->s == '\r'))
        p->s++;
}

static int value(parser *p, json_value *v, int depth);

static int string(parser *p, char **out)
{
    p->s++; /* the opening quote */
    size_t cap = 16, n = 0;
    char *buf = malloc(cap);
    while (buf && p->s < p->end && *p->s != '"') {
        char c = *p->s++;
        if ((unsigned char)c < 0x20)
            break;
        if (c == '\\') {
            if (p->s >= p->end)
                break;
            char e = *p->s++;
            c = e == 'n' ? '\n' : e == 't' ? '\t' : e == 'r' ? '\r' : e == 'b' ? '\b' : e == 'f' ? '\f'
              : (e == '"' || e == '\\' || e == '/') ? e : 0;
            if (!c) /* \u escapes: not needed by edit scripts */
                break;
        }
        if (n + 2 > cap) {
            char *grown = realloc(buf, cap *= 2);
            if (!grown)
                break;
            buf = grown;
        }
        buf[n++] = c;
    }
    if (!buf || p->s >= p->end || *p->s != '"') {
        free(buf);
        return fail(p, "a string that does not end, or holds a control character or an unsupported escape");
    }
    p->s++;
    buf[n] = '\0';
    *out = buf;
    return 1;
}

static int number(parser *p, json_value *v)
{
    char *stop = NULL;
    char tmp[64];
    size_t n = 0;
    while (p->s + n < p->end && n < sizeof tmp - 1 && strchr("+-0123456789.eE", p->s[n]))
        n++;
    memcpy(tmp, p->s, n);
    tmp[n] = '\0';
    v->number = strtod(tmp, &stop);
    if (n == 0 || stop != tmp + n)
        return fail(p, "a malformed number");
    v->type = JSON_NUMBER;
    p->s += n;
    return 1;
}

static int word(parser *p, const char *w)
{
    size_t n = strlen(w);
    if ((size_t)(p->end - p->s) < n || memcmp(p->s, w, n))
        return 0;
    p->s += n;
    return 1;
}

/* The members of an array or object, after its opening bracket. */
static int members(parser *p, json_value *v, int object, int depth)
{
    p->s++;
    size_t cap = 0;
    skip_space(p);
    char close = object ? '}' : ']';
    if (p->s < p->end && *p->s == close) {
        p->s++;
        return 1;
    }
    for (;;) {
        if (v->count == cap) {
            cap = cap ? 2 * cap : 4;
            json_value *items = realloc(v->items, cap * sizeof *items);
            char **keys = object ? realloc(v->keys, cap * sizeof *keys) : NULL;
            if (items)
                v->items = items;
            if (keys)
                v->keys = keys;
            if (!items || (object && !keys))
                return fail(p, "out of memory");
        }
        skip_space(p);
        char *key = NULL;
        if (object) {
            if (p->s >= p->end || *p->s != '"' || !string(p, &key))
                return fail(p, "an object member without a quoted name");
            v->keys[v->count] = key;
            skip_space(p);
            if (p->s >= p->end || *p->s != ':')
                return v->count++, fail(p, "a member name without ':' after it");
            p->s++;
        }
        memset(&v->items[v->count], 0, sizeof v->items[v->count]);
        v->count++;
        if (!value(p, &v->items[v->count - 1], depth + 1))
            return 0;
        skip_space(p);
        if (p->s < p->end && *p->s == ',') {
            p->s++;
            continue;
        }
        if (p->s < p->end && *p->s == close) {
            p->s++;
            return 1;
        }
        return fail(p, object ? "a missing ',' or '}'" : "a missing ',' or ']'");
    }
}

static int value(parser *p, json_value *v, int depth)
{
    if (depth > MAX_DEPTH)
        return fail(p, "nesting deeper than 64 levels");
    skip_space(p);
    if (p->s >= p->end)
        return fail(p, "the text ends where a value should be");
    char c = *p->s;
    if (c == '{' || c == '[') {
        v->type = c == '{' ? JSON_OBJECT : JSON_ARRAY;
        return members(p, v, c == '{', depth);
    }
    if (c == '"')
        return v->type = JSON_STRING, string(p, &v->string);
    if (word(p, "true"))
        return v->type = JSON_BOOL, v->number = 1.0, 1;
    if (word(p, "false"))
        return v->type = JSON_BOOL, v->number = 0.0, 1;
    if (word(p, "null"))
        return v->type = JSON_NULL, 1;
    return number(p, v);
}

static void release(json_value *v)
{
    free(v->string);
    for (size_t i = 0; i < v->count; i++) {
        release(&v->items[i]);
        if (v->keys)
            free(v->keys[i]);
    }
    free(v->items);
    free(v->keys);
}

void json_free(json_value *v)
{
    if (v)
        release(v), free(v);
}

json_value *json_parse(const char *text, size_t len, char *err, size_t err_size)
{
    parser p = {text, text + len, err, err_size, 0};
    json_value *root = calloc(1, sizeof *root);
    if (!root) {
        snprintf(err, err_size, "out of memory");
        return NULL;
    }
    int ok = value(&p, root, 0);
    skip_space(&p);
    if (ok && p.s != p.end)
        ok = fail(&p, "text after the value");
    if (!ok) {
        int line = 1, col = 1;
        for (const char *q = text; q < p.s; q++)
            line += *q == '\n', col = *q == '\n' ? 1 : col + 1;
        char what[256];
        snprintf(what, sizeof what, "%s", err);
        snprintf(err, err_size, "line %d, column %d: %s", line, col, what);
        json_free(root);
        return NULL;
    }
    return root;
}

const json_value *json_get(const json_value *v, const char *key)
{
    if (!v || v->type != JSON_OBJECT)
        return NULL;
    for (size_t i = 0; i < v->count; i++)
        if (!strcmp(v->keys[i], key))
            return &v->items[i];
    return NULL;
}
