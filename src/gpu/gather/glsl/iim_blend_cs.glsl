// The IIM's display (iim.h). Per texel: commit it (old = what it showed, new = fresh, its clock restarted),
// then display = mix(old, new, t), t from the frames since its last commit, clamped to [old, new] so
// rounding never leaves the interval; a texel turning valid or invalid shows its new value at once. Each
// commit also keeps the texel's change, delta = new - old, for the estimates of the texels that wait.
// The passes of one frame, in order (3 and 1 in one dispatch, 4 and 2 in another: neither of a pair reads
// what the other writes):
// mode 3: the flag changes in `ops` (which cells wait: mode 0 leaves their estimate on display).
// mode 1: only commits, of the cells listed in `list` (texels regathered on their own, texel_change.h),
// shown at once when instant.
// mode 0: every atlas cell; a cell is committed when its surface is (param[s].x; y: an instant commit).
// mode 4: the cells of `list` again: each starts its blend from the estimate (rebase).
// mode 2: the waiting cells listed in `redraw`: texels whose hemisphere changed and that wait for their
// gather show their own blend plus the changes of the texels of their chart within `spread` texels
// between two commits after their own last one (a change they have not seen), weighted (1 - d^2/R^2)^2
// and by how far each has blended in, divided by at least 1 (a lone far neighbour lends little): the
// coarse first estimate of progressive refinement. A waiting cell with an estimate of its own (`sight`, a 1:
// the change of what its rays see since its gather, update/ray_estimate.h) shows its own blend plus that,
// averaged with its waiting neighbours' within sight_spread texels (iim.h), instead, or (a 2: many rays) alone; in
// the frame its texel is gathered (a -1) its commit carries what it showed, and it is not rebased.
#version 450 core
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba32f) uniform readonly image2D fresh;
layout(binding = 1, rgba32f) uniform image2D old_map;
layout(binding = 2, rgba32f) uniform image2D new_map;
layout(binding = 3, rgba32f) uniform image2D display;
layout(binding = 4, rgba32f) uniform image2D delta;
layout(binding = 5, rgba32f) uniform image2D carry;
layout(binding = 6, rgba32f) uniform readonly image2D sight;
layout(std430, binding = 0) readonly buffer Surfaces { int surf[]; };
layout(std430, binding = 1) readonly buffer Params { vec2 param[]; }; /* commit, instant */
layout(std430, binding = 2) buffer Starts { int start[]; };          /* per cell: frame of its last commit */
layout(std430, binding = 3) readonly buffer List { int list[]; };
layout(std430, binding = 4) readonly buffer Charts { int chart[]; };  /* per cell: its chart, -1 in gutters */
layout(std430, binding = 5) readonly buffer Redraw { int redraw[]; };  /* waiting cells to draw */
layout(std430, binding = 6) buffer Flags { int waiting[]; };           /* per cell: 1 while it waits */
layout(std430, binding = 7) readonly buffer Ops { int ops[]; };        /* cell + 1: waits, -(cell + 1): no longer */
uniform ivec2 size;
uniform int mode, frame, blend_frames, list_count, row, instant, spread, sight_spread, sight_blend, sight_apart;
uniform int mode2, count2; /* a second list pass in one dispatch (iim.c, dispatch_lists), after the first's */
uniform float limit; /* back-face fraction above which a texel is invalid */
const int NEVER = -1073741824;
const float INSIDE = 1e30;

// The commit's own frame already shows 1 / blend_frames of the step: with none shown there, a texel
// committed again every frame (gathered every update while a node moves beside it) would keep its first
// value for as long as the commits go on; so it follows them as a running mean over about blend_frames.
// A texel committed again k frames after its commit before blends over k frames (at most blend_frames): one
// regathered every update beside a node that keeps moving shows its gathers as they come, where a running
// mean over blend_frames trailed the node (the moving cube's own faces 10% off for 54 updates); one
// regathered after a long wait, or for the first time, fades in over blend_frames.
float blend_len(ivec2 g, int c)
{
    float most = imageLoad(carry, g).a > 0.5 ? min(float(blend_frames), float(sight_blend)) : float(blend_frames);
    float before = imageLoad(delta, g).a;
    if (before >= INSIDE || before < -1e8) return most; /* none (NEVER), or out of geometry */
    return clamp(float(start[c]) - before, 1.0, most);
}
float blend_t_at(ivec2 g, int c, int f)
{
    return blend_frames <= 0 ? 1.0 : min(1.0, float(f - start[c] + 1) / blend_len(g, c));
}
float blend_t(ivec2 g, int c) { return blend_t_at(g, c, frame); }

// The texel's own blend of old and new at frame f.
vec4 own_at(ivec2 g, int c, int f)
{
    vec4 o = imageLoad(old_map, g), n = imageLoad(new_map, g);
    float t = blend_t_at(g, c, f);
    if ((o.a <= limit) != (n.a <= limit)) t = 1.0; /* turned valid or invalid: no blend with the inside */
    /* blended in: new itself (mix may be o + t (n - o), a rounding away from n, and a bake then differed
     * from a fresh one's by an ulp where old was not new) */
    return t >= 1.0 ? n : clamp(mix(o, n, t), min(o, n), max(o, n));
}
vec4 own(ivec2 g, int c) { return own_at(g, c, frame); }

// old and new stay clean (without a pending texel's estimate), so that each commit's change is the gather's
// own: old is the texel's own blend as the last frame showed it, and what was on screen beyond that (the
// estimate) is carried and fades out over the blend instead: no pop.
void commit(ivec2 g, int c, bool inst)
{
    vec4 n = imageLoad(fresh, g), v = own_at(g, c, frame - 1);
    /* delta.a: the commit before this one (what came after a waiting texel's own gather is the part it has
     * not seen), or INSIDE where the texel was inside geometry: it has no change, only its new value */
    imageStore(delta, g, vec4(n.rgb - v.rgb, v.a > limit ? INSIDE : float(start[c])));
    bool toggled = (v.a > limit) != (n.a > limit); /* shown new at once */
    /* carry.a: it showed an estimate of its own, which its gather only refines (blend_len) */
    float own_estimate = imageLoad(sight, g).a < -0.5 ? 1.0 : 0.0;
    imageStore(carry, g, inst || toggled ? vec4(0.0) : vec4(imageLoad(display, g).rgb - v.rgb, own_estimate));
    imageStore(old_map, g, v);
    imageStore(new_map, g, n);
    start[c] = inst ? NEVER : frame;
}

// The texel's own blend plus what its last commit carried, fading with the blend.
vec4 shown(ivec2 g, int c)
{
    vec4 v = own(g, c);
    return vec4(max(v.rgb + (1.0 - blend_t(g, c)) * imageLoad(carry, g).rgb, vec3(0.0)), v.a);
}

// What neighbour q (cell k, committed after this texel) says this texel's light did since its own commit:
// its change times the share of it this texel has not seen (the part of the frames between the
// neighbour's last two commits after this texel's; frame 0 is the first solution, before which nothing
// changed), or, where the neighbour came out of geometry and has no change, the step to its value.
vec3 told(ivec2 q, int k, vec3 mine, int since)
{
    vec4 d = imageLoad(delta, q);
    if (d.a >= INSIDE) return own(q, k).rgb - mine;
    float s0 = max(d.a, 0.0), s1 = float(start[k]), sc = max(float(since), 0.0);
    float unseen = s1 > s0 ? clamp((s1 - max(s0, sc)) / (s1 - s0), 0.0, 1.0) : 0.0;
    return unseen * blend_t(q, k) * d.rgb;
}

// The texel's value `mine` plus what its neighbours committed after frame `since` lend it, weighed
// (header), and kept between its own value and those its lenders show now: an estimate is never more
// extreme than what is around it.
vec3 lent(ivec2 g, int c, vec3 mine, int since, bool same_frame)
{
    float R = float(spread) + 1.0, W = 0.0;
    vec3 sum = vec3(0.0), lo = mine, hi = mine;
    for (int dy = -spread; dy <= spread; dy++)
        for (int dx = -spread; dx <= spread; dx++) {
            ivec2 q = g + ivec2(dx, dy);
            float u = 1.0 - float(dx * dx + dy * dy) / (R * R);
            if (u <= 0.0 || q.x < 0 || q.y < 0 || q.x >= size.x || q.y >= size.y) continue;
            int k = q.y * size.x + q.x;
            bool after = same_frame ? k != c && start[k] >= since && start[k] != NEVER : start[k] > since;
            if (chart[k] != chart[c] || !after || imageLoad(new_map, q).a > limit) continue;
            sum += u * u * told(q, k, mine, since);
            W += u * u;
            vec3 theirs = own(q, k).rgb;
            lo = min(lo, theirs), hi = max(hi, theirs);
        }
    return clamp(mine + sum / max(W, 1.0), max(lo, vec3(0.0)), hi);
}

// The change the rays of a waiting texel and of its chart's waiting neighbours within sight_spread texels saw, each
// weighed by a tent: one texel's few rays mottle; the neighbours' see about the same change.
vec3 seen_change(ivec2 g, int c)
{
    vec3 sum = vec3(0.0);
    float W = 0.0, mine = dot(own(g, c).rgb, vec3(1.0));
    for (int dy = -sight_spread; dy <= sight_spread; dy++)
        for (int dx = -sight_spread; dx <= sight_spread; dx++) {
            ivec2 q = g + ivec2(dx, dy);
            if (q.x < 0 || q.y < 0 || q.x >= size.x || q.y >= size.y) continue;
            vec4 d = imageLoad(sight, q);
            if (d.a <= 0.5 || chart[q.y * size.x + q.x] != chart[c]) continue;
            float w = float((sight_spread + 1 - abs(dx)) * (sight_spread + 1 - abs(dy)));
            /* and by how alike the two showed before: a texel in a moved cube's old contact shadow averages
             * with the shadow's, not with the lit floor beside it, whose light did not change */
            float theirs = dot(own(q, q.y * size.x + q.x).rgb, vec3(1.0));
            float unlike = (theirs - mine) / (0.25 * max(max(theirs, mine), 1e-6));
            w *= exp(-unlike * unlike);
            /* and by how close in time their last commits were: each change is since its own texel's gather, so
             * one gathered before a shadow came holds the shadow's whole fall, one gathered in it only the last
             * part (a floor texel under the animated box's cube showed 3.7 where its own rays said 2.6 and a
             * fresh bake 2.5); an instant commit (NEVER: the first gather, a bake) counts as frame 0 */
            int k = q.y * size.x + q.x;
            float apart = (float(start[k] == NEVER ? 0 : start[k]) - float(start[c] == NEVER ? 0 : start[c])) /
                          float(sight_apart);
            w *= exp(-apart * apart);
            sum += w * d.rgb;
            W += w;
        }
    return sum / W;
}

vec4 estimate(ivec2 g, int c)
{
    vec4 v = shown(g, c);
    if (v.a > limit) return v;
    vec4 s = imageLoad(sight, g);
    if (s.a > 1.5) return vec4(max(v.rgb + s.rgb, vec3(0.0)), v.a); /* alone (iim.h) */
    if (s.a > 0.5) return vec4(max(v.rgb + seen_change(g, c), vec3(0.0)), v.a);
    return vec4(lent(g, c, v.rgb, start[c], false), v.a);
}

// A texel committed on its own this frame starts its blend from what its neighbours lend it since its
// previous commit, those committed in this frame too: it fades in from the estimate its waiting
// neighbours show, not from its stale value (one texel fading in among them is a square).
void rebase(ivec2 g, int c)
{
    vec4 d = imageLoad(delta, g), o = imageLoad(old_map, g), n = imageLoad(new_map, g);
    if (d.a >= INSIDE || start[c] != frame || (o.a > limit) != (n.a > limit) || n.a > limit) return;
    if (imageLoad(sight, g).a != 0.0) return; /* it showed its own estimate, which its commit carries */
    vec4 v = shown(g, c);
    /* between the old value and the gathered one: a start no further out than either (a lamp switched at
     * every update otherwise sent texels 3% past both of their converged values) */
    vec3 e = clamp(lent(g, c, v.rgb, int(d.a), true), min(v.rgb, n.rgb), max(v.rgb, n.rgb));
    imageStore(carry, g, vec4(imageLoad(carry, g).rgb + e - v.rgb, 0.0));
    imageStore(display, g, shown(g, c));
}

void main() {
    ivec2 g = ivec2(gl_GlobalInvocationID.xy);
    if (mode != 0) {
        int k = g.y * row + g.x, m = mode;
        if (k >= list_count) {
            k -= list_count, m = mode2;
            if (k >= count2) return;
        }
        if (m == 3) {
            waiting[abs(ops[k]) - 1] = ops[k] > 0 ? 1 : 0;
            return;
        }
        int c = m == 1 || m == 4 ? list[k] : redraw[k];
        ivec2 q = ivec2(c % size.x, c / size.x);
        if (m == 1)
            commit(q, c, instant != 0);
        else if (m == 4)
            rebase(q, c);
        else
            imageStore(display, q, waiting[c] != 0 ? estimate(q, c) : shown(q, c));
        return;
    }
    if (g.x >= size.x || g.y >= size.y) return;
    int c = g.y * size.x + g.x, s = surf[c];
    if (s < 0) return;
    if (param[s].x > 0.5) commit(g, c, param[s].y > 0.5);
    if (waiting[c] == 0) imageStore(display, g, shown(g, c)); /* a waiting one keeps its estimate */
}
