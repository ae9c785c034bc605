/* The GLSL of src/gpu/ embedded at build time (the Makefile runs it; docs/architecture.md, "Shaders"):
 *
 *   glsl_embed OUT.c OUT.h FILE.glsl...
 *
 * writes OUT.c, one `const char lm_glsl_NAME[]` per file (NAME its base name, unique over all files),
 * and OUT.h, their declarations. Each is rewritten only when its text changes, so that the Makefile may
 * run this on every build: nothing is rebuilt when no shader changed, an edited shader recompiles OUT.c
 * alone, and only a file added or removed changes OUT.h. Each file's text is what the GL receives, but for two
 * things done here:
 *   - a line `#include "PATH"` (PATH relative to the including file) is replaced by that file's text:
 *     how a block shared by several shaders is written once;
 *   - a line whose first non-blank characters are `//` is left out: the files' own documentation,
 *     which the GL never sees (comments the GL should see are written `/ * ... * /`, as before).
 * Exit status 1, with a message naming the file, on an unreadable file, a bad name, a name used twice or
 * includes nested deeper than 8. Plain C11 and stdio: no tool beyond the compiler. */
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    char *text;
    size_t len, cap;
} buf;

static void put(buf *b, const char *s, size_t n)
{
    if (b->len + n + 1 > b->cap) {
        b->cap = (b->len + n + 1) * 2;
        b->text = realloc(b->text, b->cap);
        if (!b->text) {
            fprintf(stderr, "glsl_embed: out of memory\n");
            exit(1);
        }
    }
    memcpy(b->text + b->len, s, n);
    b->len += n;
    b->text[b->len] = '\0';
}

static void expand(const char *path, int depth, buf *out)
{
    if (depth > 8) {
        fprintf(stderr, "glsl_embed: %s: includes nested deeper than 8\n", path);
        exit(1);
    }
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "glsl_embed: cannot read %s\n", path);
        exit(1);
    }
    char line[4096];
    while (fgets(line, sizeof line, f)) {
        const char *p = line;
        while (*p == ' ' || *p == '\t')
            p++;
        if (p[0] == '/' && p[1] == '/')
            continue;
        char name[1024];
        if (sscanf(line, "#include \"%1000[^\"]\"", name) == 1) {
            char inc[4096];
            const char *slash = strrchr(path, '/');
            int dir = slash ? (int)(slash - path + 1) : 0;
            snprintf(inc, sizeof inc, "%.*s%s", dir, path, name);
            expand(inc, depth + 1, out);
            continue;
        }
        put(out, line, strlen(line));
    }
    fclose(f);
}

/* lm_glsl_ + the base name without .glsl, which must be a C identifier. */
static void symbol(const char *path, char *out, size_t size)
{
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    size_t n = strlen(base);
    if (n <= 5 || strcmp(base + n - 5, ".glsl") != 0 || n - 5 + 9 > size) {
        fprintf(stderr, "glsl_embed: %s: not NAME.glsl\n", path);
        exit(1);
    }
    snprintf(out, size, "lm_glsl_%.*s", (int)(n - 5), base);
    for (const char *c = out; *c; c++)
        if (!(isalnum((unsigned char)*c) || *c == '_')) {
            fprintf(stderr, "glsl_embed: %s: the name is not a C identifier\n", path);
            exit(1);
        }
}

static void puts_buf(buf *b, const char *s) { put(b, s, strlen(s)); }

/* A C string literal per line of text, escaped. */
static void literal(buf *out, const buf *b)
{
    if (!b->len) {
        puts_buf(out, "    \"\"");
        return;
    }
    int open = 0;
    for (size_t i = 0; i < b->len; i++) {
        unsigned char c = (unsigned char)b->text[i];
        char esc[8];
        if (!open)
            puts_buf(out, "    \""), open = 1;
        if (c == '\n')
            puts_buf(out, "\\n\"\n"), open = 0;
        else if (c == '"' || c == '\\' || c < 32 || c > 126) {
            snprintf(esc, sizeof esc, c == '"' || c == '\\' ? "\\%c" : "\\%03o", c);
            puts_buf(out, esc);
        } else
            put(out, (const char *)&c, 1);
    }
    if (open)
        puts_buf(out, "\"\n");
}

/* Writes text to path unless the file holds it already. */
static int write_if_changed(const char *path, const buf *text)
{
    FILE *old = fopen(path, "rb");
    if (old) {
        buf o = {0};
        char chunk[4096];
        size_t n;
        while ((n = fread(chunk, 1, sizeof chunk, old)) > 0)
            put(&o, chunk, n);
        fclose(old);
        int same = o.len == text->len && (!o.len || memcmp(o.text, text->text, o.len) == 0);
        free(o.text);
        if (same)
            return 1;
    }
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(text->text, 1, text->len, f) != text->len || fclose(f) != 0) {
        fprintf(stderr, "glsl_embed: cannot write %s\n", path);
        return 0;
    }
    return 1;
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: glsl_embed OUT.c OUT.h FILE.glsl...\n");
        return 1;
    }
    char (*names)[128] = calloc((size_t)argc, sizeof *names);
    if (!names) {
        fprintf(stderr, "glsl_embed: out of memory\n");
        return 1;
    }
    buf c = {0}, h = {0};
    const char *head = "/* Generated by tools/glsl_embed.c from src/gpu's .glsl files: edit those, not this. */\n";
    puts_buf(&c, head);
    puts_buf(&h, head);
    puts_buf(&h, "#ifndef LM_GLSL_H\n#define LM_GLSL_H\n\n");
    for (int i = 3; i < argc; i++) {
        symbol(argv[i], names[i], sizeof names[i]);
        for (int j = 3; j < i; j++)
            if (strcmp(names[i], names[j]) == 0) {
                fprintf(stderr, "glsl_embed: %s and %s have the same name\n", argv[j], argv[i]);
                return 1;
            }
        buf text = {0};
        expand(argv[i], 0, &text);
        char line[512];
        snprintf(line, sizeof line, "\n/* %s */\nconst char %s[] =\n", argv[i], names[i]);
        puts_buf(&c, line);
        literal(&c, &text);
        puts_buf(&c, ";\n");
        free(text.text);
        snprintf(line, sizeof line, "extern const char %s[]; /* %s */\n", names[i], argv[i]);
        puts_buf(&h, line);
    }
    puts_buf(&h, "\n#endif\n");
    int ok = write_if_changed(argv[1], &c) && write_if_changed(argv[2], &h);
    free(c.text);
    free(h.text);
    free(names);
    return ok ? 0 : 1;
}
