// The full-screen fragment shader: for every output pixel, its direction on the sphere (by
// the view), the recipe's map as compiled stages (the rows the CPU kernels read), then the
// source texel with a mip level from the derivative of the source direction.
//
// The stage codes and field offsets (STAGE_MOBIUS, DROSTE_RHO, ...) are not written here:
// the server sends spherewarp.render.stages.glsl_header(), generated from the stage table,
// and it is prepended to this body. Each stage below mirrors its kernel in
// spherewarp/render/_kernels.py (same formulas, float32).

export const VERTEX = `#version 300 es
in vec2 pos;
void main() { gl_Position = vec4(pos, 0.0, 1.0); }
`;

// the GLSL of a recipe's expression maps (the server's functions expr0, expr1, ...) and the
// function that chooses one by its slot; the text of the functions is the server's, made
// from fixed pieces (spherewarp/viewer/glsl.py), never from what the user typed
export function withExpressions(body, glsl, slots) {
  let pick = "vec2 exprEval(int slot, int s, vec2 z) {\n";
  for (let k = 0; k < slots; k++) pick += `  if (slot == ${k}) return expr${k}(s, z);\n`;
  pick += "  return z;\n}\n";
  return body.replace("//@EXPRESSIONS@", () => `${glsl}\n${pick}`);
}

export const BODY = `
uniform sampler2D uImage;   // the panorama, mipmapped, RGBA8
uniform sampler2D uPattern; // the paper's test pattern, for the overlay
uniform float uOverlay;     // how much of the test pattern is mixed in (0: none)
uniform highp sampler2D uParams;  // R32F: row s = stage s's parameter row
uniform highp sampler2D uLabels;  // R32F: a masked Schottky stage's labels (width x height)
uniform int uCodes[MAX_STAGES];
uniform int uCount;          // number of stages; -1: the map has none (show a pattern)
uniform int uView;           // 0 flat, 1 sphere, 2 little planet
uniform vec2 uSize;          // the panel in pixels
uniform vec2 uOrigin;        // the panel's left edge in the canvas (side by side)
uniform vec3 uLook;          // yaw, pitch (radians), field of view (radians, horizontal)
uniform float uPlanet;       // little planet: scale of the plane
uniform int uSS;             // sub-samples per pixel along each axis (1 to 4)
out vec4 color;

const float PI = 3.14159265358979;

float P(int s, int i) {
  return texelFetch(uParams, ivec2(i, s), 0).r;
}

// (sign, Re q, Im q) of the null vector (t, x, y, z), as _kernels._affine
vec3 affine(vec4 v) {
  float sg = v.w >= 0.0 ? 1.0 : -1.0;
  float s = -1.0 / (v.x + abs(v.w));
  return vec3(sg, v.y * s, sg * (v.z * s));
}

// the point (q, 1) (sg = 1) or (1, q) as a null vector with t = 1, as _kernels._put_pair
vec4 putPair(float sg, vec2 q) {
  float r2 = dot(q, q);
  float inv = 1.0 / (1.0 + r2);
  return vec4(1.0, -2.0 * q.x * inv, -2.0 * sg * q.y * inv, sg * (1.0 - r2) * inv);
}

vec2 cmul(vec2 a, vec2 b) { return vec2(a.x * b.x - a.y * b.y, a.x * b.y + a.y * b.x); }

// -- complex arithmetic for the expression stage (maps.expression's functions, NumPy's
// principal branches; a value beyond BIG stands for the point at infinity) -------------------
const float BIG = 3.0e38;
vec2 cadd(vec2 a, vec2 b) { return a + b; }
vec2 csub(vec2 a, vec2 b) { return a - b; }
float chypot(vec2 a) {
  float m = max(abs(a.x), abs(a.y));
  if (m == 0.0) return 0.0;
  vec2 u = a / m;
  return m * sqrt(dot(u, u));
}
vec2 cinv(vec2 a) {
  float m = max(abs(a.x), abs(a.y));
  if (m == 0.0) return vec2(BIG, 0.0);
  vec2 u = a / m;
  return vec2(u.x, -u.y) / (dot(u, u) * m);
}
vec2 cdiv(vec2 a, vec2 b) {  // Smith's division: no overflow on the way
  if (b == vec2(0.0)) return a == vec2(0.0) ? vec2(BIG) : vec2(BIG, 0.0);
  if (abs(b.x) >= abs(b.y)) {
    float r = b.y / b.x, d = b.x + b.y * r;
    return vec2(a.x + a.y * r, a.y - a.x * r) / d;
  }
  float r = b.x / b.y, d = b.x * r + b.y;
  return vec2(a.x * r + a.y, a.y * r - a.x) / d;
}
vec2 cexp(vec2 a) { return exp(a.x) * vec2(cos(a.y), sin(a.y)); }
vec2 clog(vec2 a) {
  float m = chypot(a);
  return m == 0.0 ? vec2(-BIG, 0.0) : vec2(log(m), atan(a.y, a.x));
}
vec2 csqrt(vec2 a) {
  float m = chypot(a);
  if (m == 0.0) return vec2(0.0);
  if (a.x >= 0.0) {
    float t = sqrt(0.5 * (m + a.x));
    return vec2(t, a.y / (2.0 * t));
  }
  float t = sqrt(0.5 * (m - a.x));
  return vec2(abs(a.y) / (2.0 * t), a.y < 0.0 ? -t : t);
}
vec2 csin(vec2 a) { return vec2(sin(a.x) * cosh(a.y), cos(a.x) * sinh(a.y)); }
vec2 ccos(vec2 a) { return vec2(cos(a.x) * cosh(a.y), -sin(a.x) * sinh(a.y)); }
vec2 csinh(vec2 a) { return vec2(sinh(a.x) * cos(a.y), cosh(a.x) * sin(a.y)); }
vec2 ccosh(vec2 a) { return vec2(cosh(a.x) * cos(a.y), sinh(a.x) * sin(a.y)); }
vec2 ctan(vec2 a) {
  if (abs(a.y) > 20.0) return vec2(0.0, a.y > 0.0 ? 1.0 : -1.0);
  float d = cos(2.0 * a.x) + cosh(2.0 * a.y);
  return d == 0.0 ? vec2(BIG, 0.0) : vec2(sin(2.0 * a.x), sinh(2.0 * a.y)) / d;
}
vec2 ctanh(vec2 a) {
  if (abs(a.x) > 20.0) return vec2(a.x > 0.0 ? 1.0 : -1.0, 0.0);
  float d = cosh(2.0 * a.x) + cos(2.0 * a.y);
  return d == 0.0 ? vec2(BIG, 0.0) : vec2(sinh(2.0 * a.x), sin(2.0 * a.y)) / d;
}
vec2 cabs(vec2 a) { return vec2(chypot(a), 0.0); }
vec2 cconj(vec2 a) { return vec2(a.x, -a.y); }
// as NumPy's complex power: integer exponents below 100 by repeated squaring
vec2 cpow(vec2 u, vec2 v) {
  if (v == vec2(0.0)) return vec2(1.0, 0.0);
  if (u == vec2(0.0)) return v.y == 0.0 && v.x > 0.0 ? vec2(0.0) : vec2(BIG);
  if (v.y == 0.0 && v.x == floor(v.x) && abs(v.x) < 100.0) {
    int n = int(abs(v.x));
    vec2 r = vec2(1.0, 0.0), b = u;
    for (int k = 0; k < 7; k++) {
      if ((n & 1) == 1) r = cmul(r, b);
      n >>= 1;
      if (n == 0) break;
      b = cmul(b, b);
    }
    return v.x < 0.0 ? cdiv(vec2(1.0, 0.0), r) : r;
  }
  return cexp(cmul(v, clog(u)));
}
// the expression stage's numbers: (re, im) pairs from EXPRESSION_CONSTANTS
vec2 K(int s, int k) {
  return vec2(P(s, EXPRESSION_CONSTANTS + k), P(s, EXPRESSION_CONSTANTS + k + 1));
}

// the Lorentz matrix at offset o of stage s's row (row-major there: L[col][row] in GLSL)
mat4 lorentz(int s, int o) {
  mat4 L;
  for (int i = 0; i < 4; i++)
    for (int j = 0; j < 4; j++) L[j][i] = P(s, o + 4 * i + j);
  return L;
}

vec4 stageMobius(int s, vec4 v) { return lorentz(s, MOBIUS_L00) * v; }

vec4 stagePower(int s, vec4 v) {
  float m = P(s, POWER_M);
  int am = int(abs(m));
  vec3 a = affine(v);
  vec2 q = a.yz;
  vec2 b = vec2(1.0, 0.0);
  for (int k = 0; k < 1024; k++) {
    if (k >= am) break;
    b = cmul(b, q);
  }
  return putPair(a.x * (m > 0.0 ? 1.0 : -1.0), b);
}

vec4 stageExp(int s, vec4 v) {
  float lam = P(s, EXP_LAM), near = P(s, EXP_NEAR);
  float t = v.x, x = v.y, y = v.z, z = v.w;
  float d = x < 0.0 ? (y * y + z * z) / (t - x) : t + x;
  if (d < near * t) return vec4(1.0, 0.0, 0.0, z >= 0.0 ? 1.0 : -1.0);
  float phi = -lam * y / d;
  float sr = -lam * z / d;
  float e = exp(-abs(sr));
  float w = 1.0 / (1.0 + e * e);
  float zs = (1.0 - e * e) * w;
  return vec4(1.0, 2.0 * e * cos(phi) * w, -2.0 * e * sin(phi) * w, sr <= 0.0 ? zs : -zs);
}

vec4 stageRational(int s, vec4 v) {
  int d = int(P(s, RATIONAL_DEGREE));
  int on = RATIONAL_COEFFICIENTS;
  int od = RATIONAL_COEFFICIENTS + 2 * (d + 1);
  vec3 a = affine(v);
  vec2 q = a.yz;
  bool up = a.x > 0.0;
  vec2 n = vec2(0.0), dd = vec2(0.0);
  for (int j = 0; j < 4096; j++) {
    if (j > d) break;
    int k = up ? j : d - j;  // (q, 1): highest degree first; (1, q): the lists backwards
    n = cmul(n, q) + vec2(P(s, on + 2 * k), P(s, on + 2 * k + 1));
    dd = cmul(dd, q) + vec2(P(s, od + 2 * k), P(s, od + 2 * k + 1));
  }
  float a2 = dot(n, n), b2 = dot(dd, dd), tt = a2 + b2;
  if (!(tt > 0.0)) return vec4(1.0, 0.0, 0.0, 1.0);
  float inv = 1.0 / tt;
  return vec4(1.0, -2.0 * (n.x * dd.x + n.y * dd.y) * inv, -2.0 * (n.y * dd.x - n.x * dd.y) * inv,
              (b2 - a2) * inv);
}

vec4 stageDroste(int s, vec4 v) {
  int m = int(P(s, DROSTE_M));
  float ell = P(s, DROSTE_ELL);
  vec2 beta = vec2(P(s, DROSTE_BETA_RE), P(s, DROSTE_BETA_IM));
  float l0 = P(s, DROSTE_PIVOT);
  vec2 c = vec2(P(s, DROSTE_C_RE), P(s, DROSTE_C_IM));
  float t = v.x, x = v.y, y = v.z, z = v.w;
  float rxy = sqrt(x * x + y * y);
  float lq = log(max(rxy / (t + abs(z)), 1e-30));
  float u = (z >= 0.0 ? lq : -lq) - l0;
  float th = atan(-y, -x);
  float lr = beta.x * u - beta.y * th + c.x;
  float li = beta.x * th + beta.y * u + c.y;
  float ths = li - 2.0 * PI * floor((li + PI) / (2.0 * PI));
  float xi = (ths + PI) * float(m) / (2.0 * PI);
  float i0f = clamp(floor(xi), 0.0, float(m - 1));
  float f = xi - i0f;
  int i0 = int(i0f);
  int i1 = i0 + 1 < m ? i0 + 1 : 0;
  float rho = P(s, DROSTE_RHO + i0) * (1.0 - f) + P(s, DROSTE_RHO + i1) * f;
  float us = lr - floor((lr - rho) / ell) * ell;
  us = clamp(us, rho, rho + ell);
  float e = exp(-abs(us));
  float w = 1.0 / (1.0 + e * e);
  float zs = (1.0 - e * e) * w;
  return vec4(1.0, -2.0 * e * cos(ths) * w, -2.0 * e * sin(ths) * w, us <= 0.0 ? zs : -zs);
}

// returns t < 0 for a point still in a disk after depth moves (invalid)
vec4 stageSchottky(int s, vec4 v) {
  int nm = 2 * int(P(s, SCHOTTKY_COUNT));
  int depth = int(P(s, SCHOTTKY_DEPTH));
  int last = -1;
  for (int it = 0; it <= 4096; it++) {
    int move = -1;
    for (int j = 0; j < 512; j++) {
      if (j >= nm) break;
      int b = SCHOTTKY_MOVES + j * SCHOTTKY_MOVES_SIZE;
      float dn = P(s, b + SCHOTTKY_MOVES_NX) * v.y + P(s, b + SCHOTTKY_MOVES_NX + 1) * v.z +
                 P(s, b + SCHOTTKY_MOVES_NX + 2) * v.w;
      if (j != (last ^ 1) && dn > P(s, b + SCHOTTKY_MOVES_COS_R) * v.x) { move = j; break; }
    }
    if (move < 0) return v;
    if (it >= depth) return vec4(-1.0, 0.0, 0.0, 0.0);
    v = lorentz(s, SCHOTTKY_MOVES + move * SCHOTTKY_MOVES_SIZE + SCHOTTKY_MOVES_L00) * v;
    v /= v.x;
    last = move;
  }
  return vec4(-1.0, 0.0, 0.0, 0.0);
}

// the masked Schottky stage's label at the homogeneous point v (as _kernels._mask_label)
int maskLabel(int s, vec4 v) {
  vec3 p = v.yzw / v.x;
  float lon = atan(p.y, p.x), lat = atan(p.z, length(p.xy));
  int w = int(P(s, SCHOTTKY_MASK_WIDTH)), h = int(P(s, SCHOTTKY_MASK_HEIGHT));
  int ix = int(floor((lon + PI) * float(w) / (2.0 * PI)));
  ix = ((ix % w) + w) % w;
  int iy = clamp(int(floor((0.5 * PI - lat) * float(h) / PI)), 0, h - 1);
  return int(texelFetch(uLabels, ivec2(ix, iy), 0).r);
}

// as _kernels._stage_schottky_mask: move 2i (D_x) where the label is i, then X; move 2i + 1
// (D_X) where the label of X^-1 of the point is not i; t < 0: still in a disk after depth
vec4 stageSchottkyMask(int s, vec4 v) {
  int nm = 2 * int(P(s, SCHOTTKY_MASK_COUNT));
  int depth = int(P(s, SCHOTTKY_MASK_DEPTH));
  int last = -1;
  for (int it = 0; it <= 4096; it++) {
    int move = -1;
    vec4 v2 = v;
    int here = maskLabel(s, v);
    for (int j = 0; j < 512; j++) {
      if (j >= nm) break;
      if (j == (last ^ 1)) continue;
      int i = j >> 1;
      if ((j & 1) == 0 && here != i) continue;
      v2 = lorentz(s, SCHOTTKY_MASK_DATA + 16 * j) * v;
      if ((j & 1) == 0 || maskLabel(s, v2) != i) { move = j; break; }
    }
    if (move < 0) return v;
    if (it >= depth) return vec4(-1.0, 0.0, 0.0, 0.0);
    v = v2 / v2.x;
    last = move;
  }
  return vec4(-1.0, 0.0, 0.0, 0.0);
}

// the expression maps of the recipe: vec2 expr<slot>(int s, vec2 z), made by the server from
// each expression's tree (spherewarp.viewer.glsl), and exprEval(slot, s, z) choosing one
//@EXPRESSIONS@

// w = f(z) in the chart's coordinate (0 at the zenith): z from the null vector as the power
// stage reads it, w back as a null vector; a non-finite w is the point at infinity
vec4 stageExpression(int s, vec4 v) {
  vec3 a = affine(v);
  vec2 z = a.x > 0.0 ? a.yz : cinv(a.yz);
  vec2 w = exprEval(int(P(s, EXPRESSION_SLOT)), s, z);
  if (!(abs(w.x) <= 1e37 && abs(w.y) <= 1e37)) return vec4(1.0, 0.0, 0.0, -1.0);
  return dot(w, w) <= 1.0 ? putPair(1.0, w) : putPair(-1.0, cinv(w));
}

// the output pixel's direction on the sphere, by the view (x from the left, y from the top)
vec3 outDir(vec2 p) {
  if (uView == 0) {
    float lon = p.x / uSize.x * 2.0 * PI - PI;
    float lat = 0.5 * PI - p.y / uSize.y * PI;
    return vec3(cos(lat) * cos(lon), cos(lat) * sin(lon), sin(lat));
  }
  vec2 ndc = (2.0 * p - uSize) / uSize.x;  // x in [-1, 1], y down
  if (uView == 1) {
    float cy = cos(uLook.x), sy = sin(uLook.x), cp = cos(uLook.y), sp = sin(uLook.y);
    vec3 f = vec3(cp * cy, cp * sy, sp), r = vec3(-sy, cy, 0.0), u = vec3(-sp * cy, -sp * sy, cp);
    float k = tan(0.5 * uLook.z);
    return normalize(f + k * ndc.x * r - k * ndc.y * u);
  }
  // little planet: stereographic projection from the zenith, the nadir at the centre
  vec2 q = ndc * uPlanet;
  float cy = cos(uLook.x), sy = sin(uLook.x);
  q = vec2(cy * q.x - sy * q.y, sy * q.x + cy * q.y);
  float r2 = dot(q, q);
  return vec3(2.0 * q.x, -2.0 * q.y, r2 - 1.0) / (1.0 + r2);
}

vec4 runStages(vec3 d) {
  vec4 v = vec4(1.0, d);
  for (int s = 0; s < MAX_STAGES; s++) {
    if (s >= uCount) break;
    int code = uCodes[s];
    if (code == STAGE_MOBIUS) v = stageMobius(s, v);
    else if (code == STAGE_POWER) v = stagePower(s, v);
    else if (code == STAGE_EXP) v = stageExp(s, v);
    else if (code == STAGE_RATIONAL) v = stageRational(s, v);
    else if (code == STAGE_DROSTE) v = stageDroste(s, v);
    else if (code == STAGE_SCHOTTKY) v = stageSchottky(s, v);
    else if (code == STAGE_SCHOTTKY_MASK) v = stageSchottkyMask(s, v);
    else if (code == STAGE_EXPRESSION) v = stageExpression(s, v);
    if (v.x < 0.0) return v;
  }
  return v;
}

// d lon, d lat of a change dv of the unit direction s (continuous across the seam)
vec2 lonlatGrad(vec3 s, vec3 dv) {
  float r2 = max(s.x * s.x + s.y * s.y, 1e-12);
  float dlon = (s.x * dv.y - s.y * dv.x) / r2;
  float dlat = dv.z / sqrt(r2);
  vec2 g = vec2(dlon / (2.0 * PI), dlat / PI);
  // a jump of the map (a Droste seam, a Schottky disk edge): not a footprint
  return length(dv) > 0.25 ? vec2(0.0) : g;
}

vec4 sampleAt(vec2 p, float n) {
  vec4 v = runStages(outDir(p));
  vec3 s = v.x < 0.0 ? vec3(1.0, 0.0, 0.0) : normalize(v.yzw);
  float lon = atan(s.y, s.x);
  float lat = atan(s.z, length(s.xy));
  vec2 uv = vec2((lon + PI) / (2.0 * PI), (0.5 * PI - lat) / PI);
  vec3 dx = dFdx(s) / n, dy = dFdy(s) / n;  // the footprint of one sub-sample
  vec2 gx = lonlatGrad(s, dx), gy = lonlatGrad(s, dy);
  vec4 c = textureGrad(uImage, uv, gx, gy);
  if (uOverlay > 0.0) c = mix(c, textureGrad(uPattern, uv, gx, gy), uOverlay);
  return v.x < 0.0 ? vec4(0.0, 0.0, 0.0, 1.0) : vec4(c.rgb, 1.0);
}

void main() {
  vec2 p = vec2(gl_FragCoord.x - uOrigin.x, uSize.y - gl_FragCoord.y);
  if (uCount < 0) {  // no compiled stages: a grey check so that it is plain
    float c = mod(floor(p.x / 16.0) + floor(p.y / 16.0), 2.0);
    color = vec4(vec3(0.35 + 0.1 * c), 1.0);
    return;
  }
  // uSS x uSS sub-samples a pixel (a box filter, as the CPU's area anti-aliasing), each
  // with the mip level of its own footprint
  float n = float(uSS);
  vec4 acc = vec4(0.0);
  for (int i = 0; i < 4; i++) {
    if (i >= uSS) break;
    for (int j = 0; j < 4; j++) {
      if (j >= uSS) break;
      acc += sampleAt(p + (vec2(float(i), float(j)) + 0.5) / n - 0.5, n);
    }
  }
  color = acc / (n * n);
}
`;
