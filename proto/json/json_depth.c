/*
 * json_depth.c - see json_depth.h. One pass, no allocation: it runs on
 * hostile bodies before the memory budget has seen their tree.
 */
#include "json_depth.h"

int json_depth_exceeds(const char *text, size_t size, int limit, int *line, int *column)
{
    int depth = 0, in_string = 0, escaped = 0, ln = 1;
    size_t line_start = 0;
    for (size_t i = 0; i < size; i++) {
        char ch = text[i];
        if (ch == '\n') {
            ln++;
            line_start = i + 1;
        }
        if (in_string) {
            if (escaped)
                escaped = 0;
            else if (ch == '\\')
                escaped = 1;
            else if (ch == '"')
                in_string = 0;
        } else if (ch == '"') {
            in_string = 1;
        } else if (ch == '[' || ch == '{') {
            if (++depth > limit) {
                if (line)
                    *line = ln;
                if (column)
                    *column = (int)(i - line_start + 1);
                return 1;
            }
        } else if ((ch == ']' || ch == '}') && depth > 0) {
            depth--;
        }
    }
    return 0;
}
