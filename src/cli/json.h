/* A small JSON reader for the command line's own input files (edit scripts): the whole text parsed into
 * a tree of values, numbers as doubles. Strict: one value, no trailing commas or comments; an error says
 * at which line and column the text stops making sense. Depth is limited to 64 levels. */
#ifndef LM_CLI_JSON_H
#define LM_CLI_JSON_H

#include <stddef.h>

typedef enum { JSON_NULL, JSON_BOOL, JSON_NUMBER, JSON_STRING, JSON_ARRAY, JSON_OBJECT } json_type;

typedef struct json_value json_value;
struct json_value {
    json_type type;
    double number;         /* JSON_NUMBER; JSON_BOOL: 0 or 1 */
    char *string;          /* JSON_STRING (NUL-terminated, escapes decoded) */
    json_value *items;     /* JSON_ARRAY and JSON_OBJECT: count values */
    char **keys;           /* JSON_OBJECT: count keys, in file order */
    size_t count;
};

/* Parses text (len bytes). Returns the root (free with json_free) or NULL with the reason in err. */
json_value *json_parse(const char *text, size_t len, char *err, size_t err_size);
void json_free(json_value *v);
/* The member `key` of an object (the first if repeated), NULL if absent or v is not an object. */
const json_value *json_get(const json_value *v, const char *key);

#endif
