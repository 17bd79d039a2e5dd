(function(){const t=document.createElement("link").relList;if(t&&t.supports&&t.supports("modulepreload"))return;for(const r of document.querySelectorAll('link[rel="modulepreload"]'))o(r);new MutationObserver(r=>{for(const a of r)if(a.type==="childList")for(const c of a.addedNodes)c.tagName==="LINK"&&c.rel==="modulepreload"&&o(c)}).observe(document,{childList:!0,subtree:!0});function s(r){const a={};return r.integrity&&(a.integrity=r.integrity),r.referrerPolicy&&(a.referrerPolicy=r.referrerPolicy),r.crossOrigin==="use-credentials"?a.credentials="include":r.crossOrigin==="anonymous"?a.credentials="omit":a.credentials="same-origin",a}function o(r){if(r.ep)return;r.ep=!0;const a=s(r);fetch(r.href,a)}})();const _e=`#version 300 es
in vec2 pos;
void main() { gl_Position = vec4(pos, 0.0, 1.0); }
`;function Ae(e,t,s){let o=`vec2 exprEval(int slot, int s, vec2 z) {
`;for(let r=0;r<s;r++)o+=`  if (slot == ${r}) return expr${r}(s, z);
`;return o+=`  return z;
}
`,e.replace("//@EXPRESSIONS@",()=>`${t}
${o}`)}const Oe=`
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
`,J=32,k=Math.PI/180,p=e=>document.getElementById(e),E=p("view"),$=p("marks"),g=(e,t=!1)=>{p("status").textContent=e,p("status").className=t?"bad":"",p("status").setAttribute("role",t?"alert":"status"),p("status").setAttribute("aria-live",t?"assertive":"polite")},n={recipe:{spherewarp:1,steps:[]},view:"flat",side:null,mode:null,size:[1024,512],look:[0,0,90],planet:1,pins:[[0,90],[0,-90]],undo:[],redo:[],stages:null,image:null,frames:0,overlay:0,ss:2,marks:!0},i=E.getContext("webgl2",{preserveDrawingBuffer:!0,antialias:!1}),Re=["uImage","uParams","uCodes","uCount","uView","uSize","uLook","uPlanet","uSS","uPattern","uOverlay","uLabels","uOrigin"];let S={},ee=null,te=null,fe="";const B=new Map;let le=null;function de(e,t){const s=`${t}
${e}`;if(le===s)return;let o=B.get(s);if(!o){if(!/^[A-Za-z0-9_\s(){},;=+\-*]*$/.test(e))throw new Error("unexpected expression GLSL");const r=`#version 300 es
precision highp float;
precision highp int;
#define MAX_STAGES ${J}
${fe}
${Ae(Oe,e,t)}`,a=(u,d)=>{const f=i.createShader(u);if(i.shaderSource(f,d),i.compileShader(f),!i.getShaderParameter(f,i.COMPILE_STATUS))throw new Error(i.getShaderInfoLog(f));return f},c=i.createProgram();if(i.attachShader(c,a(i.VERTEX_SHADER,_e)),i.attachShader(c,a(i.FRAGMENT_SHADER,r)),i.bindAttribLocation(c,0,"pos"),i.linkProgram(c),!i.getProgramParameter(c,i.LINK_STATUS))throw new Error(i.getProgramInfoLog(c));const l={};for(const u of Re)l[u]=i.getUniformLocation(c,u);o={prog:c,uni:l},B.size>16&&B.clear(),B.set(s,o)}i.useProgram(o.prog),S=o.uni,le=s}function ze(e){fe=e,de("",0);const t=i.createBuffer();i.bindBuffer(i.ARRAY_BUFFER,t),i.bufferData(i.ARRAY_BUFFER,new Float32Array([-1,-1,3,-1,-1,3]),i.STATIC_DRAW),i.enableVertexAttribArray(0),i.vertexAttribPointer(0,2,i.FLOAT,!1,0,0)}function U(e,t=0,s=null){return s=s||i.createTexture(),i.activeTexture(i.TEXTURE0+t),i.bindTexture(i.TEXTURE_2D,s),i.pixelStorei(i.UNPACK_COLORSPACE_CONVERSION_WEBGL,i.NONE),i.pixelStorei(i.UNPACK_PREMULTIPLY_ALPHA_WEBGL,!1),i.texImage2D(i.TEXTURE_2D,0,i.RGBA8,i.RGBA,i.UNSIGNED_BYTE,e),i.generateMipmap(i.TEXTURE_2D),i.texParameteri(i.TEXTURE_2D,i.TEXTURE_MIN_FILTER,i.LINEAR_MIPMAP_LINEAR),i.texParameteri(i.TEXTURE_2D,i.TEXTURE_MAG_FILTER,i.LINEAR),i.texParameteri(i.TEXTURE_2D,i.TEXTURE_WRAP_S,i.REPEAT),i.texParameteri(i.TEXTURE_2D,i.TEXTURE_WRAP_T,i.CLAMP_TO_EDGE),s}let he=null;function ue(){const e=n.video;e.readyState<2||(n.videoTime=e.currentTime,U(e,0,he),T(),ce()&&ke(),p("vtime").textContent=`${e.currentTime.toFixed(2)} s`,!n.seeking&&e.duration&&(p("vseek").value=e.currentTime/e.duration))}async function Ie(){const e=document.createElement("video");e.muted=!0,e.loop=!0,e.playsInline=!0,e.preload="auto";const t=new Promise((o,r)=>{e.addEventListener("loadeddata",o,{once:!0}),e.addEventListener("error",()=>r(new Error(`video: ${e.error?e.error.message||`error ${e.error.code}`:"cannot play"} (the browser may lack its codec)`)),{once:!0})});e.src="video",await t,n.video=e,he=U(e,0);const s=()=>{e.currentTime!==n.videoTime&&!e.seeking&&ue(),requestAnimationFrame(s)};requestAnimationFrame(s),e.addEventListener("seeked",ue),p("vctl").hidden=!1,p("play").onclick=()=>e.paused?e.play():e.pause(),e.addEventListener("play",()=>p("play").textContent="Pause"),e.addEventListener("pause",()=>p("play").textContent="Play"),p("vseek").oninput=()=>{n.seeking=!0,e.currentTime=+p("vseek").value*(e.duration||0)},p("vseek").onchange=()=>n.seeking=!1,e.play().catch(()=>p("play").textContent="Play")}const Le=["mobius","power","exp","rational","droste","schottky","schottky_mask","expression"];function pe(e,t,s,o,r){i.activeTexture(i.TEXTURE0+t),i.bindTexture(i.TEXTURE_2D,e),i.pixelStorei(i.UNPACK_ALIGNMENT,1),i.texImage2D(i.TEXTURE_2D,0,i.R32F,s,o,0,i.RED,i.FLOAT,r),i.texParameteri(i.TEXTURE_2D,i.TEXTURE_MIN_FILTER,i.NEAREST),i.texParameteri(i.TEXTURE_2D,i.TEXTURE_MAG_FILTER,i.NEAREST)}async function Ne(e){if(n.labelsKey===e.key)return;const t=await fetch(`api/labels/${e.key}`);if(!t.ok)throw new Error(`labels: HTTP ${t.status}`);const s=new Int16Array(await t.arrayBuffer());te||(te=i.createTexture()),pe(te,3,e.width,e.height,Float32Array.from(s)),n.labelsKey=e.key}async function me(e){if(n.stages={codes:null},e.codes===null){g(`no live preview: ${e.missing}`,!0);return}const t=e.codes.map(c=>n.stageNames[c]).filter(c=>!Le.includes(c));if(t.length){g(`no live preview: the shader has no '${t[0]}' stage yet (render full resolution)`,!0);return}if(e.codes.length>J){g(`no live preview: ${e.codes.length} stages (the shader takes ${J})`,!0);return}const s=e.labels||[];if(s.length>1){g("no live preview: the shader takes one masked Schottky group",!0);return}const o=e.codes.filter(c=>n.stageNames[c]==="expression").length;try{de(e.glsl||"",o),s.length&&await Ne(s[0])}catch(c){g(`no live preview: ${c.message}`,!0);return}const r=Math.max(1,...e.rows.map(c=>c.length)),a=new Float32Array(r*Math.max(1,e.rows.length));e.rows.forEach((c,l)=>a.set(c,l*r)),ee||(ee=i.createTexture()),pe(ee,1,r,Math.max(1,e.rows.length),a),n.stages=e}function C(){const e={view:n.view,edited:!0};return n.side?n.side==="original"?[e,{view:n.view,edited:!1}]:[e,{view:n.side,edited:!0}]:[e]}function T(){const[e,t]=n.size,s=C();(E.width!==e*s.length||E.height!==t)&&(E.width=e*s.length,E.height=t);const o=new Int32Array(J);n.stages&&n.stages.codes&&o.set(n.stages.codes),i.uniform1iv(S.uCodes,o),i.uniform1i(S.uImage,0),i.uniform1i(S.uParams,1),i.uniform1i(S.uPattern,2),i.uniform1i(S.uLabels,3),i.uniform2f(S.uSize,e,t),i.uniform3f(S.uLook,n.look[0]*k,n.look[1]*k,n.look[2]*k),i.uniform1f(S.uPlanet,n.planet),i.uniform1i(S.uSS,n.ss),i.uniform1f(S.uOverlay,n.overlay);const r=n.stages&&n.stages.codes?n.stages.codes.length:-1;s.forEach((a,c)=>{i.viewport(c*e,0,e,t),i.uniform2f(S.uOrigin,c*e,0),i.uniform1i(S.uCount,a.edited?r:0),i.uniform1i(S.uView,{flat:0,sphere:1,planet:2}[a.view]),i.drawArrays(i.TRIANGLES,0,3)}),n.frames+=1,N()}function N(){const[e,t]=n.size,s=C();($.width!==E.width||$.height!==E.height)&&($.width=E.width,$.height=E.height);const o=$.getContext("2d");o.clearRect(0,0,$.width,$.height);const r=(c,l,u,d=5)=>{o.beginPath(),o.arc(c,l,d,0,2*Math.PI),o.lineWidth=3,o.strokeStyle="black",o.stroke(),o.lineWidth=1.5,o.strokeStyle=u,o.stroke()},a=(c,l,u,d,f)=>{const h=f?[...c,c[0]]:c;o.lineWidth=1.5,o.strokeStyle=l,o.beginPath();let m=null;for(const y of h){const v=O(y[0],y[1],d);v&&m&&Math.abs(v[0]-m[0])<e/2?o.lineTo(u+v[0],v[1]):v&&o.moveTo(u+v[0],v[1]),m=v}o.stroke()};s.forEach((c,l)=>{const u=l*e;if(o.save(),o.beginPath(),o.rect(u,0,e,t),o.clip(),l>0&&(o.fillStyle="#1d1f21",o.fillRect(u,0,1,t)),c.edited){for(const f of n.marks?n.pins:[]){const h=O(f[0],f[1],c.view);h&&r(u+h[0],h[1],"#ffd54a")}n.marks&&De(o,u,c.view,a,r);const d=n.mode;d&&d.kind==="droste"&&(d.points.forEach(f=>{const h=O(f[0],f[1],c.view);h&&r(u+h[0],h[1],"#4ae3ff",4)}),d.points.length>1&&a(we(d.points,!1),"#4ae3ff",u,c.view,!1)),d&&d.kind==="schottky"&&(d.cur?[...d.disks,d.cur]:d.disks).forEach((h,m)=>a(j(h),m%2?"#ff7a4a":"#7aff4a",u,c.view,!0))}o.restore()})}const V=e=>typeof e=="number"&&Number.isFinite(e),se=e=>Array.isArray(e)&&e.length>=2&&V(e[0])&&V(e[1]),ne=e=>se(e)&&e.length===3&&V(e[2]),$e=e=>!!e&&typeof e=="object"&&Array.isArray(e.keyframes),Ce=()=>ce()&&n.at?n.at:n.recipe,ve=(e,t)=>t.reduce((s,o)=>s[o],e.steps);function re(e=Ce()){const t=[],s=[];return(e.steps||[]).forEach((o,r)=>{if(o.droste){const a=o.droste;Array.isArray(a.frame)&&a.frame.length===4&&a.frame.every(se)&&(t.push({pts:we(a.frame,!0),closed:!1,colour:"#ff4ae3"}),a.frame.forEach((c,l)=>s.push({at:c,colour:"#ff4ae3",path:[r,"droste","frame",l]}))),se(a.center)&&(V(a.inner_radius)&&t.push({pts:j([...a.center,a.inner_radius]),closed:!0,colour:"#ff4ae3"}),s.push({at:a.center,colour:"#ff4ae3",path:[r,"droste","center"]}))}o.schottky&&Array.isArray(o.schottky.generators)&&o.schottky.generators.forEach((a,c)=>{!a||!ne(a.disk)||(t.push({pts:j(a.disk),closed:!0,colour:"#7aff4a"}),s.push({at:a.disk,colour:"#7aff4a",path:[r,"schottky","generators",c,"disk"],disk:!0}),ne(a.to)&&(t.push({pts:j(a.to),closed:!0,colour:"#ff7a4a"}),s.push({at:a.to,colour:"#ff7a4a",path:[r,"schottky","generators",c,"to"],disk:!0}),t.push({pts:oe(a.disk,a.to),closed:!1,colour:"#ffffff",arrow:!0})))}),o.schottky&&Array.isArray(o.schottky.targets)&&o.schottky.targets.forEach((a,c)=>{!a||!ne(a.to)||(t.push({pts:j(a.to),closed:!0,colour:"#ff7a4a"}),s.push({at:a.to,colour:"#ff7a4a",path:[r,"schottky","targets",c,"to"],disk:!0}))})}),{shapes:t,handles:s}}function De(e,t,s,o,r){const{shapes:a,handles:c}=re();for(const l of a)if(o(l.pts,l.colour,t,s,l.closed),l.arrow){const u=l.pts.slice(-6).map(h=>O(h[0],h[1],s)),[d,f]=[u[0],u[u.length-1]];if(d&&f&&Math.hypot(f[0]-d[0],f[1]-d[1])>1&&Math.abs(f[0]-d[0])<n.size[0]/2){const h=Math.atan2(f[1]-d[1],f[0]-d[0]);e.beginPath();for(const m of[-1,1])e.moveTo(t+f[0],f[1]),e.lineTo(t+f[0]-8*Math.cos(h+m*.4),f[1]-8*Math.sin(h+m*.4));e.stroke()}}for(const l of c){const u=O(l.at[0],l.at[1],s);u&&r(t+u[0],u[1],l.colour,3.5)}}function je(){const e=[];if(!n.marks)return e;const{handles:t}=re();return C().forEach((s,o)=>{if(s.edited)for(const r of t){const a=O(r.at[0],r.at[1],s.view);a&&a[0]>=0&&a[0]<n.size[0]&&a[1]>=0&&a[1]<n.size[1]&&e.push({path:r.path,panel:o,x:o*n.size[0]+a[0],y:a[1]})}}),e}function qe(e,t,s){if(!n.marks)return null;const{handles:o}=re();let r=null,a=8;for(const c of o){const l=O(c.at[0],c.at[1],s),u=l?Math.hypot(l[0]-e,l[1]-t):1/0;u<=a&&(r=c,a=u)}if(r)return r;a=5;for(const c of o.filter(l=>l.disk)){const l=j(c.at).map(u=>O(u[0],u[1],s));l.forEach((u,d)=>{const f=l[(d+1)%l.length];if(!u||!f||Math.abs(f[0]-u[0])>=n.size[0]/2)return;const h=Xe([e,t],u,f);h<=a&&(r={...c,radius:!0},a=h)})}return r}function Xe(e,t,s){const[o,r]=[s[0]-t[0],s[1]-t[1]],a=Math.max(0,Math.min(1,((e[0]-t[0])*o+(e[1]-t[1])*r)/(o*o+r*r||1)));return Math.hypot(t[0]+a*o-e[0],t[1]+a*r-e[1])}function ye(e,t,s,o=0){const r=JSON.parse(JSON.stringify(e)),a=ve(r,t.path.slice(0,-1)),c=t.path[t.path.length-1],l=a[c];return t.radius?a[c]=[l[0],l[1],M([ae(l,s)])[0]]:a[c]=ge(l,l.length===3?[...M(s),l[2]]:M(s),o),r}function ge(e,t,s){if($e(e)){const o=e.keyframes.filter(r=>Math.abs(r[0]-s)>1e-9);return o.push([s,t]),{...e,keyframes:o.sort((r,a)=>r[0]-a[0])}}return Array.isArray(e)&&Array.isArray(t)?t.map((o,r)=>ge(e[r],o,s)):t}const I=e=>{const[t,s]=[e[0]*k,e[1]*k];return[Math.cos(s)*Math.cos(t),Math.cos(s)*Math.sin(t),Math.sin(s)]},W=e=>[Math.atan2(e[1],e[0])/k,Math.atan2(e[2],Math.hypot(e[0],e[1]))/k],ae=(e,t)=>{const[s,o]=[I(e),I(t)];return Math.acos(Math.max(-1,Math.min(1,s[0]*o[0]+s[1]*o[1]+s[2]*o[2])))/k};function we(e,t){const s=[],o=t?e.length:e.length-1;for(let r=0;r<o;r++){const[a,c]=[I(e[r]),I(e[(r+1)%e.length])];for(let l=0;l<=16;l++){const u=l/16;s.push(W(a.map((d,f)=>d*(1-u)+c[f]*u)))}}return s}function oe(e,t){let[s,o]=[I(e),I(t)];const r=s[0]*o[0]+s[1]*o[1]+s[2]*o[2];if(r<-.999){const l=Math.abs(s[2])<.9?[0,0,1]:[1,0,0],u=W(l.map((d,f)=>d-(l[0]*s[0]+l[1]*s[1]+l[2]*s[2])*s[f]));return[...oe(e,u),...oe(u,t).slice(1)]}const a=Math.acos(Math.max(-1,Math.min(1,r))),c=[];for(let l=0;l<=32;l++){const u=l/32,[d,f]=a<1e-9?[1-u,u]:[Math.sin((1-u)*a)/Math.sin(a),Math.sin(u*a)/Math.sin(a)];c.push(W(s.map((h,m)=>d*h+f*o[m])))}return c}function j(e){const t=I(e),s=Math.abs(t[2])<.9?[0,0,1]:[1,0,0],o=s[0]*t[0]+s[1]*t[1]+s[2]*t[2];let r=s.map((d,f)=>d-o*t[f]);const a=Math.hypot(...r);r=r.map(d=>d/a);const c=[t[1]*r[2]-t[2]*r[1],t[2]*r[0]-t[0]*r[2],t[0]*r[1]-t[1]*r[0]],l=e[2]*k,u=[];for(let d=0;d<72;d++){const f=2*Math.PI*d/72;u.push(W(t.map((h,m)=>Math.cos(l)*h+Math.sin(l)*(Math.cos(f)*r[m]+Math.sin(f)*c[m]))))}return u}function Q(e,t,s=n.view){const[o,r]=n.size;if(s==="flat")return[e/o*360-180,90-t/r*180];const a=(2*e-o)/o,c=(2*t-r)/o;let l;if(s==="sphere"){const[f,h,m]=n.look.map(D=>D*k),y=Math.cos(f),v=Math.sin(f),P=Math.cos(h),_=Math.sin(h),b=Math.tan(m/2);l=[P*y-b*a*v+b*c*_*y,P*v+b*a*y+b*c*_*v,_-b*c*P]}else{let f=a*n.planet,h=c*n.planet;const m=Math.cos(n.look[0]*k),y=Math.sin(n.look[0]*k);[f,h]=[m*f-y*h,y*f+m*h];const v=f*f+h*h;l=[2*f/(1+v),-2*h/(1+v),(v-1)/(1+v)]}const u=Math.atan2(l[1],l[0])/k,d=Math.atan2(l[2],Math.hypot(l[0],l[1]))/k;return[u,d]}function O(e,t,s=n.view){const[o,r]=n.size;if(s==="flat")return[((e+180)%360+360)%360/360*o,(90-t)/180*r];const a=I([e,t]);let c,l;if(s==="sphere"){const[f,h,m]=n.look.map(z=>z*k),y=Math.cos(f),v=Math.sin(f),P=Math.cos(h),_=Math.sin(h),b=[P*y,P*v,_],D=[-v,y,0],x=[-_*y,-_*v,P],A=z=>z[0]*a[0]+z[1]*a[1]+z[2]*a[2],R=Math.tan(m/2);if(A(b)<=1e-6)return null;c=A(D)/(R*A(b)),l=-A(x)/(R*A(b))}else{if(a[2]>1-1e-9)return null;const f=a[0]/(1-a[2]),h=-a[1]/(1-a[2]),m=Math.cos(n.look[0]*k),y=Math.sin(n.look[0]*k);c=(m*f+y*h)/n.planet,l=(-y*f+m*h)/n.planet}const u=(c+1)*o/2,d=(l*o+r)/2;return Math.abs(u)<1e5&&Math.abs(d)<1e5?[u,d]:null}function ie(e,t=null){const s=E.getBoundingClientRect(),o=(e.clientX-s.left)*E.width/s.width,r=(e.clientY-s.top)*E.height/s.height,a=t??Math.max(0,Math.min(C().length-1,Math.floor(o/n.size[0])));return[o-a*n.size[0],r,a]}const M=e=>e.map(t=>Math.round(t*1e6)/1e6);let G=null,Z=!1;async function K(e,t){const s=await fetch(e,{method:"POST",headers:{"Content-Type":"application/json"},body:JSON.stringify(t)}),o=await s.json();if(!s.ok)throw new Error(o.error||`HTTP ${s.status}`);return o}function L(){ke(),X()}function ke(){G=JSON.parse(JSON.stringify(n.recipe)),Z||Ge()}function xe(){if(!n.video)return 0;const e=n.video.currentTime;return n.rate?Math.floor(e*n.rate+1e-4)/n.rate:e}const ce=()=>JSON.stringify(n.recipe).includes('"keyframes"');async function Ge(){for(Z=!0;G;){const e=G;G=null;try{const{stages:t,at:s}=await K(`api/stages${n.video?`?t=${xe()}`:""}`,e);n.at=s||null,await me(t),t.codes&&g([`${e.steps.length} step(s), ${t.codes.length} stage(s)`,...Ue(e)].join("; "))}catch(t){g(t.message,!0)}T()}Z=!1,n.settled=!0,window.dispatchEvent(new Event("sw-drawn"))}function Ue(e){const t=[],s=e.view&&typeof e.view=="object"?e.view:{},o=[];s.projection&&o.push(`${s.projection}`),s.fov!=null&&o.push(`fov ${s.fov}°`),s.look_at!=null&&o.push(`look_at ${JSON.stringify(s.look_at)}`),s.roll&&o.push(`roll ${s.roll}°`),Array.isArray(s.size)&&o.push(`${s.size[0]}x${s.size[1]}`),o.length&&t.push(`the preview shows the panorama; the render uses the recipe's view (${o.join(", ")})`);const r=e.options&&e.options.interp;return r&&r!=="bilinear"&&t.push(`the preview interpolates bilinearly; the render uses options.interp "${r}"`),t}function q(e){n.undo.push(JSON.stringify(n.recipe)),n.redo=[],n.recipe=e,L(),H()}function Ee(e,t){e.length&&(t.push(JSON.stringify(n.recipe)),n.recipe=JSON.parse(e.pop()),L(),H())}const Se=()=>Ee(n.undo,n.redo),be=()=>Ee(n.redo,n.undo);function X(){const e=new URLSearchParams;e.set("view",n.view),e.set("size",`${n.size[0]}x${n.size[1]}`),n.ss!==2&&e.set("ss",n.ss),n.side&&e.set("side",n.side),n.marks||e.set("marks","0"),e.set("recipe",JSON.stringify(n.recipe)),history.replaceState(null,"",`?${e}`)}function Ke(){const e=new URLSearchParams(location.search);["flat","sphere","planet"].includes(e.get("view"))&&(n.view=e.get("view"));const t=/^(\d+)x(\d+)$/.exec(e.get("size")||"");t&&(n.size=[Math.min(+t[1],8192),Math.min(+t[2],8192)]),["flat","sphere","planet","original"].includes(e.get("side"))&&(n.side=e.get("side")),e.get("marks")==="0"&&(n.marks=!1);const s=+e.get("ss");if(s>=1&&s<=4&&(n.ss=Math.round(s)),e.get("recipe"))try{n.recipe=JSON.parse(e.get("recipe"))}catch(o){g(`recipe in the URL: ${o.message}`,!0)}}let w=null;async function Te(e,t){try{await K("api/stages",e)}catch(s){return g(`${t}: ${s.message}`,!0),!1}return q(e),!0}function F(e){n.mode=e===null||n.mode&&n.mode.kind===e?null:{kind:e,points:[],disks:[],cur:null},p("m-droste").classList.toggle("on",!!n.mode&&n.mode.kind==="droste"),p("m-schottky").classList.toggle("on",!!n.mode&&n.mode.kind==="schottky"),n.mode&&n.mode.kind==="droste"&&g("Droste frame: click its four corners, in order round the frame"),n.mode&&n.mode.kind==="schottky"&&g("Schottky disks: press at a centre and drag out the radius, for D_x and then its target D_X"),N()}async function Fe(e){const t=n.mode;if(t.points.push(M(e)),N(),t.points.length<4)return g(`Droste frame: corner ${t.points.length} of 4`);const s=t.points;F(null),await Te({...n.recipe,steps:[...n.recipe.steps,{droste:{frame:s}}]},"Droste frame")&&g("Droste frame added")}async function He(e){const t=n.mode;if(t.disks.push(e),t.cur=null,N(),t.disks.length<2)return g("Schottky disks: now the target disk D_X");const s={disk:t.disks[0],to:t.disks[1]};F(null);const o=[...n.recipe.steps],r=o[o.length-1];r&&r.schottky&&Array.isArray(r.schottky.generators)?o[o.length-1]={schottky:{...r.schottky,generators:[...r.schottky.generators,s]}}:o.push({schottky:{generators:[s]}}),await Te({...n.recipe,steps:o},"Schottky disks")&&g("Schottky generator added")}E.addEventListener("mousedown",e=>{e.preventDefault();const[t,s,o]=ie(e),r=C()[o],a=Q(t,s,r.view),c=()=>w={look:!0,x:e.clientX,y:e.clientY,start:[...n.look]};if(!r.edited){r.view==="sphere"?c():g("this panel is the image unedited: edit in the other one");return}if(n.mode&&n.mode.kind==="droste")return void Fe(a);if(n.mode&&n.mode.kind==="schottky"){n.mode.cur=[...M(a),0],w={disk:!0,panel:o,view:r.view};return}const l=!e.altKey&&qe(t,s,r.view);if(l){const u=ce()&&n.at?n.at.time:0;w={handle:l,time:u,base:JSON.parse(JSON.stringify(n.recipe)),moved:!1,panel:o,view:r.view};return}if(e.altKey){n.pins=[n.pins[1],M(a)],Me(),N();return}if(r.view==="sphere"&&!e.shiftKey)return void c();w={from:M(a),base:JSON.parse(JSON.stringify(n.recipe)),moved:!1,panel:o,view:r.view}});function Pe(e,t){return{mobius:{from:[e,...n.pins],to:[M(t),...n.pins]}}}const Y=e=>{const[t,s]=ie(e,w.panel);return Q(t,s,w.view)};window.addEventListener("mousemove",e=>{if(w){if(w.look){const t=n.look[2]/(E.getBoundingClientRect().width/C().length);n.look[0]=w.start[0]+(e.clientX-w.x)*t,n.look[1]=Math.max(-89.9,Math.min(89.9,w.start[1]+(e.clientY-w.y)*t)),T();return}if(w.disk){n.mode.cur[2]=M([ae(n.mode.cur,Y(e))])[0],N();return}if(w.moved=!0,w.handle){n.recipe=ye(w.base,w.handle,Y(e),w.time),L();return}n.recipe={...w.base,steps:[...w.base.steps,Pe(w.from,Y(e))]},L()}});window.addEventListener("mouseup",e=>{if(!w)return;const t=w,s=t.look?null:Y(e);if(w=null,t.disk){const o=[...n.mode.cur.slice(0,2),M([ae(n.mode.cur,s)])[0]];return o[2]>=.5&&o[2]<90?void He(o):(n.mode.cur=null,N(),g("Schottky disks: drag out a radius (0.5 to 90 degrees) from the centre",!0))}if(!(t.look||!t.moved)){if(t.handle)return void Be(t,s);n.undo.push(JSON.stringify(t.base)),n.redo=[],n.recipe={...t.base,steps:[...t.base.steps,Pe(t.from,s)]},L(),H()}});async function Be(e,t){const s=ye(e.base,e.handle,t,e.time);n.recipe=e.base;try{await K(`api/stages?t=${e.time}`,s)}catch(r){return L(),await window.spherewarp.settle(),g(`moving the mark: ${r.message}`,!0)}q(s),await window.spherewarp.settle();const o=JSON.stringify(ve(e.base,e.handle.path)).includes('"keyframes"');g((e.handle.radius?"disk radius changed":"mark moved")+(o?` (keyframe at t = ${e.time} s)`:""))}E.addEventListener("wheel",e=>{e.preventDefault();const[t,s,o]=ie(e),r=C()[o];if((e.ctrlKey||e.metaKey||e.altKey)&&r.edited){const a=M(Q(t,s,r.view)),c=Math.exp(-e.deltaY*.002),l=[...n.recipe.steps],u=l[l.length-1];u&&u.zoom&&u.zoom.at[0]===a[0]&&u.zoom.at[1]===a[1]&&!w?l[l.length-1]={zoom:{at:a,factor:u.zoom.factor*c}}:l.push({zoom:{at:a,factor:c}}),q({...n.recipe,steps:l})}else r.view==="sphere"?(n.look[2]=Math.max(10,Math.min(170,n.look[2]*Math.exp(e.deltaY*.001))),T()):r.view==="planet"&&(n.planet=Math.max(.05,Math.min(20,n.planet*Math.exp(e.deltaY*.001))),T())},{passive:!1});window.addEventListener("keydown",e=>{if(e.key==="Escape"&&n.mode)return F(null),g("cancelled");if(!(e.ctrlKey||e.metaKey))return;const t=e.target;if(!(t instanceof HTMLElement&&(t.isContentEditable||t.tagName==="TEXTAREA"||t.tagName==="INPUT"&&!["range","checkbox","button","file"].includes(t.type)))){if(e.key==="z"&&!e.shiftKey)Se();else if(e.key==="y"||e.key==="z"&&e.shiftKey)be();else return;e.preventDefault()}});function Me(){p("pins").textContent=n.pins.map(e=>`(${e[0].toFixed(1)}, ${e[1].toFixed(1)})`).join(" ")}function Ye(e,t){const s=Math.max(1,Math.abs(e))*2,o=t||{},r=o.integer?Math.max(1,Math.round(s/500)):s/500;let a=Math.round(s/r),c=a;const l=d=>Math.max(0,Math.floor(d/r-1e-6)),u=d=>Math.max(0,Math.ceil(d/r-1e-6)-1);return o.ge!=null&&(a=Math.min(a,l(e-o.ge))),o.gt!=null&&(a=Math.min(a,u(e-o.gt))),o.le!=null&&(c=Math.min(c,l(o.le-e))),o.lt!=null&&(c=Math.min(c,u(o.lt-e))),[e-a*r,e+c*r,r]}function H(){const e=p("params");e.replaceChildren(),n.recipe.steps.forEach((t,s)=>{const[o,r]=Object.entries(t)[0],a=document.createElement("fieldset"),c=document.createElement("legend");c.textContent=`${s+1}. ${o}`;const l=document.createElement("button");l.textContent="×",l.title="remove this step",l.onclick=()=>q({...n.recipe,steps:n.recipe.steps.filter((f,h)=>h!==s)}),c.append(" ",l),a.append(c);const u=(f,h,m,y)=>{const v=h(),[P,_,b]=Ye(v,y),D=document.createElement("label"),x=document.createElement("input");x.type="range",x.min=P,x.max=_,x.step=b,x.value=v;const A=document.createElement("span");A.textContent=(+v).toPrecision(5);let R=null,z=v;x.oninput=()=>{R===null&&(R=JSON.stringify(n.recipe)),y&&y.nonzero&&+x.value==0&&(x.value=z>0?-b:b),z=+x.value,m(+x.value),A.textContent=(+x.value).toPrecision(5),L()},x.onchange=()=>{R!==null&&(n.undo.push(R),n.redo=[]),R=null,H()},D.append(`${f} `,x,A),a.append(D)},d=(f,h)=>{for(const[m,y]of Object.entries(f))if(typeof y=="number"){const v=h?null:((n.params||{})[o]||{})[m];u(`${h}${m}`,()=>f[m],P=>f[m]=P,v)}else(Array.isArray(y)||y&&typeof y=="object"&&!y.keyframes)&&d(y,`${h}${m}.`)};d(r,""),e.append(a)})}function Je(e,t){const s=document.createElement("a");s.href=URL.createObjectURL(t),s.download=e,s.click()}function Ve(){const e=JSON.stringify(n.recipe,null,1),[t,s]=n.size,o=n.recipe.view,r=o&&typeof o=="object"&&Object.keys(o).length?"":` --size ${t}x${s}`,a=n.video?`spherewarp video ${n.imageName} -o out.mp4${r} recipe recipe.json`:`spherewarp render recipe.json ${n.imageName} -o out.png${r}`;return`cat > recipe.json <<'EOF'
${e}
EOF
${a}`}function We(){p("undo").onclick=Se,p("redo").onclick=be,p("save").onclick=()=>Je("recipe.json",new Blob([JSON.stringify(n.recipe,null,2)+`
`],{type:"application/json"})),p("load-button").onclick=()=>p("load").click(),p("load").onchange=async e=>{const t=e.target.files[0];if(t){e.target.value="";try{const s=JSON.parse(await t.text());await K("api/stages",s),q(s)}catch(s){g(`${t.name}: ${s.message}`,!0)}}},p("copy").onclick=async()=>{const e=Ve();p("cli").value=e;try{await navigator.clipboard.writeText(e),g("copied the command")}catch{g("the command is in the box below (the clipboard is not available)")}},p("render").onclick=async()=>{const e=p("render");if(e.disabled)return;e.disabled=!0;const t=(s,o=!1)=>{e.disabled=!1,g(s,o)};try{const s=n.video?`?t=${xe()}`:"",{job:o}=await K(`api/render${s}`,n.recipe),r=async()=>{let a;try{const l=await fetch(`api/render/${o}`);if(a=await l.json(),!l.ok)throw new Error(a.error||`HTTP ${l.status}`)}catch(l){return t(`render: no answer from the server about the render (${l.message})`,!0)}if(a.error)return t(`render: ${a.error}`,!0);if(!a.done)return g(a.started?`rendering ${(100*a.progress).toFixed(0)}%`:"waiting for an earlier render"),setTimeout(r,300);t("rendered: downloading");const c=document.createElement("a");c.href=`api/render/${o}/file`,c.download="",c.click()};r()}catch(s){t(`render: ${s.message}`,!0)}};for(const e of["flat","sphere","planet"])p(`v-${e}`).onclick=()=>{n.view=e,X(),T()};p("side").onchange=()=>{n.side=p("side").value||null,X(),T()},p("show-marks").checked=n.marks,p("show-marks").onchange=()=>{n.marks=p("show-marks").checked,X(),N()},p("m-droste").onclick=()=>F("droste"),p("m-schottky").onclick=()=>F("schottky"),p("overlay").oninput=async()=>{if(!n.patternLoaded){n.patternLoaded=!0;const e=new Image;e.src="testpattern",await e.decode(),U(e,2)}n.overlay=+p("overlay").value,T()},p("size").onchange=()=>{const e=/^(\d+)x(\d+)$/.exec(p("size").value);e&&(n.size=[+e[1],+e[2]],X(),T())}}async function Ze(){const e=await(await fetch("api/state")).json();n.imageName=e.image.name,n.rate=e.rate,n.stageNames=Object.fromEntries(e.table.stages.map(o=>[o.code,o.name])),n.params=e.params,n.recipe=e.recipe;const t=e.image.width/e.image.height;n.size=[Math.min(e.image.width,2048),Math.round(Math.min(e.image.width,2048)/t)],Ke(),p("size").value=`${n.size[0]}x${n.size[1]}`,p("side").value=n.side||"",ze(e.glsl_header);const s=new Image;s.src="image",await s.decode(),U(s),U(s,2),e.image.video&&await Ie(),We(),Me(),H(),L()}window.spherewarp={S:n,draw:T,pixelToLonLat:Q,lonLatToPixel:O,markPositions:je,setRecipe:e=>q(e),setStages:async e=>{await me(e),T()},seek:e=>new Promise(t=>{const s=n.video;s.pause();const o=()=>{if(s.seeking||n.videoTime!==s.currentTime)return requestAnimationFrame(o);window.spherewarp.settle().then(()=>t(s.currentTime))};s.addEventListener("seeked",()=>requestAnimationFrame(o),{once:!0}),s.currentTime=e}),settle:()=>new Promise(e=>{if(!Z&&!G)return e();window.addEventListener("sw-drawn",()=>e(),{once:!0})}),frameTime:e=>{const t=new Uint8Array(4),s=performance.now();for(let o=0;o<e;o++)T(),i.readPixels(0,0,1,1,i.RGBA,i.UNSIGNED_BYTE,t);return(performance.now()-s)/e}};Ze().then(()=>window.spherewarp.ready=!0).catch(e=>{g(e.message,!0),window.spherewarp.error=e.message});
