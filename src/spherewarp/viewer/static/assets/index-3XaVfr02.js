(function(){const t=document.createElement("link").relList;if(t&&t.supports&&t.supports("modulepreload"))return;for(const o of document.querySelectorAll('link[rel="modulepreload"]'))r(o);new MutationObserver(o=>{for(const a of o)if(a.type==="childList")for(const c of a.addedNodes)c.tagName==="LINK"&&c.rel==="modulepreload"&&r(c)}).observe(document,{childList:!0,subtree:!0});function s(o){const a={};return o.integrity&&(a.integrity=o.integrity),o.referrerPolicy&&(a.referrerPolicy=o.referrerPolicy),o.crossOrigin==="use-credentials"?a.credentials="include":o.crossOrigin==="anonymous"?a.credentials="omit":a.credentials="same-origin",a}function r(o){if(o.ep)return;o.ep=!0;const a=s(o);fetch(o.href,a)}})();const Oe=`#version 300 es
in vec2 pos;
void main() { gl_Position = vec4(pos, 0.0, 1.0); }
`;function Re(e,t,s){let r=`vec2 exprEval(int slot, int s, vec2 z) {
`;for(let o=0;o<s;o++)r+=`  if (slot == ${o}) return expr${o}(s, z);
`;return r+=`  return z;
}
`,e.replace("//@EXPRESSIONS@",()=>`${t}
${r}`)}const Ie=`
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
`,J=32,k=Math.PI/180,p=e=>document.getElementById(e),E=p("view"),C=p("marks"),v=(e,t=!1)=>{p("status").textContent=e,p("status").className=t?"bad":"",p("status").setAttribute("role",t?"alert":"status"),p("status").setAttribute("aria-live",t?"assertive":"polite")},n={recipe:{spherewarp:1,steps:[]},view:"flat",side:null,mode:null,size:[1024,512],look:[0,0,90],planet:1,pins:[[0,90],[0,-90]],undo:[],redo:[],stages:null,image:null,frames:0,overlay:0,ss:2,marks:!0},i=E.getContext("webgl2",{preserveDrawingBuffer:!0,antialias:!1}),Le=["uImage","uParams","uCodes","uCount","uView","uSize","uLook","uPlanet","uSS","uPattern","uOverlay","uLabels","uOrigin"];let S={},ee=null,te=null,de="";const B=new Map;let le=null;function he(e,t){const s=`${t}
${e}`;if(le===s)return;let r=B.get(s);if(!r){if(!/^[A-Za-z0-9_\s(){},;=+\-*]*$/.test(e))throw new Error("unexpected expression GLSL");const o=`#version 300 es
precision highp float;
precision highp int;
#define MAX_STAGES ${J}
${de}
${Re(Ie,e,t)}`,a=(u,d)=>{const f=i.createShader(u);if(i.shaderSource(f,d),i.compileShader(f),!i.getShaderParameter(f,i.COMPILE_STATUS))throw new Error(i.getShaderInfoLog(f));return f},c=i.createProgram();if(i.attachShader(c,a(i.VERTEX_SHADER,Oe)),i.attachShader(c,a(i.FRAGMENT_SHADER,o)),i.bindAttribLocation(c,0,"pos"),i.linkProgram(c),!i.getProgramParameter(c,i.LINK_STATUS))throw new Error(i.getProgramInfoLog(c));const l={};for(const u of Le)l[u]=i.getUniformLocation(c,u);r={prog:c,uni:l},B.size>16&&B.clear(),B.set(s,r)}i.useProgram(r.prog),S=r.uni,le=s}function $e(e){de=e,he("",0);const t=i.createBuffer();i.bindBuffer(i.ARRAY_BUFFER,t),i.bufferData(i.ARRAY_BUFFER,new Float32Array([-1,-1,3,-1,-1,3]),i.STATIC_DRAW),i.enableVertexAttribArray(0),i.vertexAttribPointer(0,2,i.FLOAT,!1,0,0)}function U(e,t=0,s=null){return s=s||i.createTexture(),i.activeTexture(i.TEXTURE0+t),i.bindTexture(i.TEXTURE_2D,s),i.pixelStorei(i.UNPACK_COLORSPACE_CONVERSION_WEBGL,i.NONE),i.pixelStorei(i.UNPACK_PREMULTIPLY_ALPHA_WEBGL,!1),i.texImage2D(i.TEXTURE_2D,0,i.RGBA8,i.RGBA,i.UNSIGNED_BYTE,e),i.generateMipmap(i.TEXTURE_2D),i.texParameteri(i.TEXTURE_2D,i.TEXTURE_MIN_FILTER,i.LINEAR_MIPMAP_LINEAR),i.texParameteri(i.TEXTURE_2D,i.TEXTURE_MAG_FILTER,i.LINEAR),i.texParameteri(i.TEXTURE_2D,i.TEXTURE_WRAP_S,i.REPEAT),i.texParameteri(i.TEXTURE_2D,i.TEXTURE_WRAP_T,i.CLAMP_TO_EDGE),s}let pe=null;function ue(){const e=n.video;e.readyState<2||(n.videoTime=e.currentTime,U(e,0,pe),T(),ce()&&xe(),p("vtime").textContent=`${e.currentTime.toFixed(2)} s`,!n.seeking&&e.duration&&(p("vseek").value=e.currentTime/e.duration))}async function Ne(){const e=document.createElement("video");e.muted=!0,e.loop=!0,e.playsInline=!0,e.preload="auto";const t=new Promise((r,o)=>{e.addEventListener("loadeddata",r,{once:!0}),e.addEventListener("error",()=>o(new Error(`video: ${e.error?e.error.message||`error ${e.error.code}`:"cannot play"} (the browser may lack its codec)`)),{once:!0})});e.src="video",await t,n.video=e,pe=U(e,0);const s=()=>{e.currentTime!==n.videoTime&&!e.seeking&&ue(),requestAnimationFrame(s)};requestAnimationFrame(s),e.addEventListener("seeked",ue),p("vctl").hidden=!1,p("play").onclick=()=>e.paused?e.play():e.pause(),e.addEventListener("play",()=>p("play").textContent="Pause"),e.addEventListener("pause",()=>p("play").textContent="Play"),p("vseek").oninput=()=>{n.seeking=!0,e.currentTime=+p("vseek").value*(e.duration||0)},p("vseek").onchange=()=>n.seeking=!1,e.play().catch(()=>p("play").textContent="Play")}const Ce=["mobius","power","exp","rational","droste","schottky","schottky_mask","expression"];function me(e,t,s,r,o){i.activeTexture(i.TEXTURE0+t),i.bindTexture(i.TEXTURE_2D,e),i.pixelStorei(i.UNPACK_ALIGNMENT,1),i.texImage2D(i.TEXTURE_2D,0,i.R32F,s,r,0,i.RED,i.FLOAT,o),i.texParameteri(i.TEXTURE_2D,i.TEXTURE_MIN_FILTER,i.NEAREST),i.texParameteri(i.TEXTURE_2D,i.TEXTURE_MAG_FILTER,i.NEAREST)}async function De(e){if(n.labelsKey===e.key)return;const t=await fetch(`api/labels/${e.key}`);if(!t.ok)throw new Error(`labels: HTTP ${t.status}`);const s=new Int16Array(await t.arrayBuffer());te||(te=i.createTexture()),me(te,3,e.width,e.height,Float32Array.from(s)),n.labelsKey=e.key}async function ve(e){if(n.stages={codes:null},e.codes===null){v(`no live preview: ${e.missing}`,!0);return}const t=e.codes.map(c=>n.stageNames[c]).filter(c=>!Ce.includes(c));if(t.length){v(`no live preview: the shader has no '${t[0]}' stage yet (render full resolution)`,!0);return}if(e.codes.length>J){v(`no live preview: ${e.codes.length} stages (the shader takes ${J})`,!0);return}const s=e.labels||[];if(s.length>1){v("no live preview: the shader takes one masked Schottky group",!0);return}const r=e.codes.filter(c=>n.stageNames[c]==="expression").length;try{he(e.glsl||"",r),s.length&&await De(s[0])}catch(c){v(`no live preview: ${c.message}`,!0);return}const o=Math.max(1,...e.rows.map(c=>c.length)),a=new Float32Array(o*Math.max(1,e.rows.length));e.rows.forEach((c,l)=>a.set(c,l*o)),ee||(ee=i.createTexture()),me(ee,1,o,Math.max(1,e.rows.length),a),n.stages=e}function O(){const e={view:n.view,edited:!0};return n.side?n.side==="original"?[e,{view:n.view,edited:!1}]:[e,{view:n.side,edited:!0}]:[e]}function T(){const[e,t]=n.size,s=O();(E.width!==e*s.length||E.height!==t)&&(E.width=e*s.length,E.height=t);const r=new Int32Array(J);n.stages&&n.stages.codes&&r.set(n.stages.codes),i.uniform1iv(S.uCodes,r),i.uniform1i(S.uImage,0),i.uniform1i(S.uParams,1),i.uniform1i(S.uPattern,2),i.uniform1i(S.uLabels,3),i.uniform2f(S.uSize,e,t),i.uniform3f(S.uLook,n.look[0]*k,n.look[1]*k,n.look[2]*k),i.uniform1f(S.uPlanet,n.planet),i.uniform1i(S.uSS,n.ss),i.uniform1f(S.uOverlay,n.overlay);const o=n.stages&&n.stages.codes?n.stages.codes.length:-1;s.forEach((a,c)=>{i.viewport(c*e,0,e,t),i.uniform2f(S.uOrigin,c*e,0),i.uniform1i(S.uCount,a.edited?o:0),i.uniform1i(S.uView,{flat:0,sphere:1,planet:2}[a.view]),i.drawArrays(i.TRIANGLES,0,3)}),n.frames+=1,N()}function N(){const[e,t]=n.size,s=O();(C.width!==E.width||C.height!==E.height)&&(C.width=E.width,C.height=E.height);const r=C.getContext("2d");r.clearRect(0,0,C.width,C.height);const o=(c,l,u,d=5)=>{r.beginPath(),r.arc(c,l,d,0,2*Math.PI),r.lineWidth=3,r.strokeStyle="black",r.stroke(),r.lineWidth=1.5,r.strokeStyle=u,r.stroke()},a=(c,l,u,d,f)=>{const h=f?[...c,c[0]]:c;r.lineWidth=1.5,r.strokeStyle=l,r.beginPath();let m=null;for(const g of h){const y=z(g[0],g[1],d);y&&m&&Math.abs(y[0]-m[0])<e/2?r.lineTo(u+y[0],y[1]):y&&r.moveTo(u+y[0],y[1]),m=y}r.stroke()};s.forEach((c,l)=>{const u=l*e;if(r.save(),r.beginPath(),r.rect(u,0,e,t),r.clip(),l>0&&(r.fillStyle="#1d1f21",r.fillRect(u,0,1,t)),c.edited){for(const f of n.marks?n.pins:[]){const h=z(f[0],f[1],c.view);h&&o(u+h[0],h[1],"#ffd54a")}n.marks&&Xe(r,u,c.view,a,o);const d=n.mode;d&&d.kind==="droste"&&(d.points.forEach(f=>{const h=z(f[0],f[1],c.view);h&&o(u+h[0],h[1],"#4ae3ff",4)}),d.points.length>1&&a(ke(d.points,!1),"#4ae3ff",u,c.view,!1)),d&&d.kind==="schottky"&&(d.cur?[...d.disks,d.cur]:d.disks).forEach((h,m)=>a(j(h),m%2?"#ff7a4a":"#7aff4a",u,c.view,!0))}r.restore()})}const V=e=>typeof e=="number"&&Number.isFinite(e),se=e=>Array.isArray(e)&&e.length>=2&&V(e[0])&&V(e[1]),ne=e=>se(e)&&e.length===3&&V(e[2]),je=e=>!!e&&typeof e=="object"&&Array.isArray(e.keyframes),qe=()=>ce()&&n.at?n.at:n.recipe,ye=(e,t)=>t.reduce((s,r)=>s[r],e.steps);function oe(e=qe()){const t=[],s=[];return(e.steps||[]).forEach((r,o)=>{if(r.droste){const a=r.droste;Array.isArray(a.frame)&&a.frame.length===4&&a.frame.every(se)&&(t.push({pts:ke(a.frame,!0),closed:!1,colour:"#ff4ae3"}),a.frame.forEach((c,l)=>s.push({at:c,colour:"#ff4ae3",path:[o,"droste","frame",l]}))),se(a.center)&&(V(a.inner_radius)&&t.push({pts:j([...a.center,a.inner_radius]),closed:!0,colour:"#ff4ae3"}),s.push({at:a.center,colour:"#ff4ae3",path:[o,"droste","center"]}))}r.schottky&&Array.isArray(r.schottky.generators)&&r.schottky.generators.forEach((a,c)=>{!a||!ne(a.disk)||(t.push({pts:j(a.disk),closed:!0,colour:"#7aff4a"}),s.push({at:a.disk,colour:"#7aff4a",path:[o,"schottky","generators",c,"disk"],disk:!0}),ne(a.to)&&(t.push({pts:j(a.to),closed:!0,colour:"#ff7a4a"}),s.push({at:a.to,colour:"#ff7a4a",path:[o,"schottky","generators",c,"to"],disk:!0}),t.push({pts:re(a.disk,a.to),closed:!1,colour:"#ffffff",arrow:!0})))}),r.schottky&&Array.isArray(r.schottky.targets)&&r.schottky.targets.forEach((a,c)=>{!a||!ne(a.to)||(t.push({pts:j(a.to),closed:!0,colour:"#ff7a4a"}),s.push({at:a.to,colour:"#ff7a4a",path:[o,"schottky","targets",c,"to"],disk:!0}))})}),{shapes:t,handles:s}}function Xe(e,t,s,r,o){const{shapes:a,handles:c}=oe();for(const l of a)if(r(l.pts,l.colour,t,s,l.closed),l.arrow){const u=l.pts.slice(-6).map(h=>z(h[0],h[1],s)),[d,f]=[u[0],u[u.length-1]];if(d&&f&&Math.hypot(f[0]-d[0],f[1]-d[1])>1&&Math.abs(f[0]-d[0])<n.size[0]/2){const h=Math.atan2(f[1]-d[1],f[0]-d[0]);e.beginPath();for(const m of[-1,1])e.moveTo(t+f[0],f[1]),e.lineTo(t+f[0]-8*Math.cos(h+m*.4),f[1]-8*Math.sin(h+m*.4));e.stroke()}}for(const l of c){const u=z(l.at[0],l.at[1],s);u&&o(t+u[0],u[1],l.colour,3.5)}}function Ge(){const e=[];if(!n.marks)return e;const{handles:t}=oe();return O().forEach((s,r)=>{if(s.edited)for(const o of t){const a=z(o.at[0],o.at[1],s.view);a&&a[0]>=0&&a[0]<n.size[0]&&a[1]>=0&&a[1]<n.size[1]&&e.push({path:o.path,panel:r,x:r*n.size[0]+a[0],y:a[1]})}}),e}function Ue(e,t,s){if(!n.marks)return null;const{handles:r}=oe();let o=null,a=8;for(const c of r){const l=z(c.at[0],c.at[1],s),u=l?Math.hypot(l[0]-e,l[1]-t):1/0;u<=a&&(o=c,a=u)}if(o)return o;a=5;for(const c of r.filter(l=>l.disk)){const l=j(c.at).map(u=>z(u[0],u[1],s));l.forEach((u,d)=>{const f=l[(d+1)%l.length];if(!u||!f||Math.abs(f[0]-u[0])>=n.size[0]/2)return;const h=Fe([e,t],u,f);h<=a&&(o={...c,radius:!0},a=h)})}return o}function Fe(e,t,s){const[r,o]=[s[0]-t[0],s[1]-t[1]],a=Math.max(0,Math.min(1,((e[0]-t[0])*r+(e[1]-t[1])*o)/(r*r+o*o||1)));return Math.hypot(t[0]+a*r-e[0],t[1]+a*o-e[1])}function ge(e,t,s,r=0){const o=JSON.parse(JSON.stringify(e)),a=ye(o,t.path.slice(0,-1)),c=t.path[t.path.length-1],l=a[c];return t.radius?a[c]=[l[0],l[1],M([ae(l,s)])[0]]:a[c]=we(l,l.length===3?[...M(s),l[2]]:M(s),r),o}function we(e,t,s){if(je(e)){const r=e.keyframes.filter(o=>Math.abs(o[0]-s)>1e-9);return r.push([s,t]),{...e,keyframes:r.sort((o,a)=>o[0]-a[0])}}return Array.isArray(e)&&Array.isArray(t)?t.map((r,o)=>we(e[o],r,s)):t}const L=e=>{const[t,s]=[e[0]*k,e[1]*k];return[Math.cos(s)*Math.cos(t),Math.cos(s)*Math.sin(t),Math.sin(s)]},W=e=>[Math.atan2(e[1],e[0])/k,Math.atan2(e[2],Math.hypot(e[0],e[1]))/k],ae=(e,t)=>{const[s,r]=[L(e),L(t)];return Math.acos(Math.max(-1,Math.min(1,s[0]*r[0]+s[1]*r[1]+s[2]*r[2])))/k};function ke(e,t){const s=[],r=t?e.length:e.length-1;for(let o=0;o<r;o++){const[a,c]=[L(e[o]),L(e[(o+1)%e.length])];for(let l=0;l<=16;l++){const u=l/16;s.push(W(a.map((d,f)=>d*(1-u)+c[f]*u)))}}return s}function re(e,t){let[s,r]=[L(e),L(t)];const o=s[0]*r[0]+s[1]*r[1]+s[2]*r[2];if(o<-.999){const l=Math.abs(s[2])<.9?[0,0,1]:[1,0,0],u=W(l.map((d,f)=>d-(l[0]*s[0]+l[1]*s[1]+l[2]*s[2])*s[f]));return[...re(e,u),...re(u,t).slice(1)]}const a=Math.acos(Math.max(-1,Math.min(1,o))),c=[];for(let l=0;l<=32;l++){const u=l/32,[d,f]=a<1e-9?[1-u,u]:[Math.sin((1-u)*a)/Math.sin(a),Math.sin(u*a)/Math.sin(a)];c.push(W(s.map((h,m)=>d*h+f*r[m])))}return c}function j(e){const t=L(e),s=Math.abs(t[2])<.9?[0,0,1]:[1,0,0],r=s[0]*t[0]+s[1]*t[1]+s[2]*t[2];let o=s.map((d,f)=>d-r*t[f]);const a=Math.hypot(...o);o=o.map(d=>d/a);const c=[t[1]*o[2]-t[2]*o[1],t[2]*o[0]-t[0]*o[2],t[0]*o[1]-t[1]*o[0]],l=e[2]*k,u=[];for(let d=0;d<72;d++){const f=2*Math.PI*d/72;u.push(W(t.map((h,m)=>Math.cos(l)*h+Math.sin(l)*(Math.cos(f)*o[m]+Math.sin(f)*c[m]))))}return u}function Q(e,t,s=n.view){const[r,o]=n.size;if(s==="flat")return[e/r*360-180,90-t/o*180];const a=(2*e-r)/r,c=(2*t-o)/r;let l;if(s==="sphere"){const[f,h,m]=n.look.map(D=>D*k),g=Math.cos(f),y=Math.sin(f),P=Math.cos(h),_=Math.sin(h),b=Math.tan(m/2);l=[P*g-b*a*y+b*c*_*g,P*y+b*a*g+b*c*_*y,_-b*c*P]}else{let f=a*n.planet,h=c*n.planet;const m=Math.cos(n.look[0]*k),g=Math.sin(n.look[0]*k);[f,h]=[m*f-g*h,g*f+m*h];const y=f*f+h*h;l=[2*f/(1+y),-2*h/(1+y),(y-1)/(1+y)]}const u=Math.atan2(l[1],l[0])/k,d=Math.atan2(l[2],Math.hypot(l[0],l[1]))/k;return[u,d]}function z(e,t,s=n.view){const[r,o]=n.size;if(s==="flat")return[((e+180)%360+360)%360/360*r,(90-t)/180*o];const a=L([e,t]);let c,l;if(s==="sphere"){const[f,h,m]=n.look.map(I=>I*k),g=Math.cos(f),y=Math.sin(f),P=Math.cos(h),_=Math.sin(h),b=[P*g,P*y,_],D=[-y,g,0],x=[-_*g,-_*y,P],A=I=>I[0]*a[0]+I[1]*a[1]+I[2]*a[2],R=Math.tan(m/2);if(A(b)<=1e-6)return null;c=A(D)/(R*A(b)),l=-A(x)/(R*A(b))}else{if(a[2]>1-1e-9)return null;const f=a[0]/(1-a[2]),h=-a[1]/(1-a[2]),m=Math.cos(n.look[0]*k),g=Math.sin(n.look[0]*k);c=(m*f+g*h)/n.planet,l=(-g*f+m*h)/n.planet}const u=(c+1)*r/2,d=(l*r+o)/2;return Math.abs(u)<1e5&&Math.abs(d)<1e5?[u,d]:null}function ie(e,t=null){const s=E.getBoundingClientRect(),r=(e.clientX-s.left)*E.width/s.width,o=(e.clientY-s.top)*E.height/s.height,a=t??Math.max(0,Math.min(O().length-1,Math.floor(r/n.size[0])));return[r-a*n.size[0],o,a]}const M=e=>e.map(t=>Math.round(t*1e6)/1e6);let X=null,Z=!1;async function F(e,t){const s=await fetch(e,{method:"POST",headers:{"Content-Type":"application/json"},body:JSON.stringify(t)}),r=await s.json();if(!s.ok)throw new Error(r.error||`HTTP ${s.status}`);return r}function $(){xe(),G()}function xe(){X=JSON.parse(JSON.stringify(n.recipe)),Z||Ke()}function Ee(){if(!n.video)return 0;const e=n.video.currentTime;return n.rate?Math.floor(e*n.rate+1e-4)/n.rate:e}const ce=()=>JSON.stringify(n.recipe).includes('"keyframes"');async function Ke(){for(Z=!0;X;){const e=X;X=null;try{const{stages:t,at:s}=await F(`api/stages${n.video?`?t=${Ee()}`:""}`,e);n.at=s||null,await ve(t),t.codes&&v([`${e.steps.length} step(s), ${t.codes.length} stage(s)`,...He(e)].join("; "))}catch(t){v(t.message,!0)}T()}Z=!1,n.settled=!0,window.dispatchEvent(new Event("sw-drawn"))}function He(e){const t=[],s=e.view&&typeof e.view=="object"?e.view:{},r=[];s.projection&&r.push(`${s.projection}`),s.fov!=null&&r.push(`fov ${s.fov}°`),s.look_at!=null&&r.push(`look_at ${JSON.stringify(s.look_at)}`),s.roll&&r.push(`roll ${s.roll}°`),Array.isArray(s.size)&&r.push(`${s.size[0]}x${s.size[1]}`),r.length&&t.push(`the preview shows the panorama; the render uses the recipe's view (${r.join(", ")})`);const o=e.options&&e.options.interp;return o&&o!=="bilinear"&&t.push(`the preview interpolates bilinearly; the render uses options.interp "${o}"`),t}function q(e){n.undo.push(JSON.stringify(n.recipe)),n.redo=[],n.recipe=e,$(),H()}function Se(e,t){e.length&&(t.push(JSON.stringify(n.recipe)),n.recipe=JSON.parse(e.pop()),$(),H())}const be=()=>Se(n.undo,n.redo),Te=()=>Se(n.redo,n.undo);function G(){const e=new URLSearchParams;e.set("view",n.view),e.set("size",`${n.size[0]}x${n.size[1]}`),n.ss!==2&&e.set("ss",n.ss),n.side&&e.set("side",n.side),n.marks||e.set("marks","0"),e.set("recipe",JSON.stringify(n.recipe)),history.replaceState(null,"",`?${e}`)}const fe=8192;function Pe(e=O().length){const t=i.getParameter(i.MAX_VIEWPORT_DIMS),s=i.getParameter(i.MAX_RENDERBUFFER_SIZE);return[Math.min(fe,Math.floor(Math.min(t[0],s)/e)),Math.min(fe,t[1],s)]}function Me(e,t=O().length){const s=/^\s*(\d+)\s*[x×]\s*(\d+)\s*$/i.exec(e||"");if(!s)throw new Error(`size: expected WIDTHxHEIGHT, such as 1024x512, got "${e}"`);const[r,o]=[+s[1],+s[2]],[a,c]=Pe(t);if(r<1||o<1||r>a||o>c)throw new Error(`size: expected a width of 1 to ${a} and a height of 1 to ${c} (what this GPU draws${t>1?`, ${t} panels side by side`:""}), got ${r}x${o}`);return[r,o]}function Be(e){try{n.size=Me(e)}catch(t){return p("size").setAttribute("aria-invalid","true"),v(t.message,!0)}p("size").removeAttribute("aria-invalid"),p("size").value=`${n.size[0]}x${n.size[1]}`,v(`size ${n.size[0]}x${n.size[1]}`),G(),T()}function Ye(){const e=new URLSearchParams(location.search);if(["flat","sphere","planet"].includes(e.get("view"))&&(n.view=e.get("view")),["flat","sphere","planet","original"].includes(e.get("side"))&&(n.side=e.get("side")),e.get("size"))try{n.size=Me(e.get("size"))}catch(s){v(`the URL's ${s.message}`,!0)}e.get("marks")==="0"&&(n.marks=!1);const t=+e.get("ss");if(t>=1&&t<=4&&(n.ss=Math.round(t)),e.get("recipe"))try{n.recipe=JSON.parse(e.get("recipe"))}catch(s){v(`recipe in the URL: ${s.message}`,!0)}}let w=null;async function _e(e,t){try{await F("api/stages",e)}catch(s){return v(`${t}: ${s.message}`,!0),!1}return q(e),!0}function K(e){n.mode=e===null||n.mode&&n.mode.kind===e?null:{kind:e,points:[],disks:[],cur:null},p("m-droste").classList.toggle("on",!!n.mode&&n.mode.kind==="droste"),p("m-schottky").classList.toggle("on",!!n.mode&&n.mode.kind==="schottky"),n.mode&&n.mode.kind==="droste"&&v("Droste frame: click its four corners, in order round the frame"),n.mode&&n.mode.kind==="schottky"&&v("Schottky disks: press at a centre and drag out the radius, for D_x and then its target D_X"),N()}async function Je(e){const t=n.mode;if(t.points.push(M(e)),N(),t.points.length<4)return v(`Droste frame: corner ${t.points.length} of 4`);const s=t.points;K(null),await _e({...n.recipe,steps:[...n.recipe.steps,{droste:{frame:s}}]},"Droste frame")&&v("Droste frame added")}async function Ve(e){const t=n.mode;if(t.disks.push(e),t.cur=null,N(),t.disks.length<2)return v("Schottky disks: now the target disk D_X");const s={disk:t.disks[0],to:t.disks[1]};K(null);const r=[...n.recipe.steps],o=r[r.length-1];o&&o.schottky&&Array.isArray(o.schottky.generators)?r[r.length-1]={schottky:{...o.schottky,generators:[...o.schottky.generators,s]}}:r.push({schottky:{generators:[s]}}),await _e({...n.recipe,steps:r},"Schottky disks")&&v("Schottky generator added")}E.addEventListener("mousedown",e=>{e.preventDefault();const[t,s,r]=ie(e),o=O()[r],a=Q(t,s,o.view),c=()=>w={look:!0,x:e.clientX,y:e.clientY,start:[...n.look]};if(!o.edited){o.view==="sphere"?c():v("this panel is the image unedited: edit in the other one");return}if(n.mode&&n.mode.kind==="droste")return void Je(a);if(n.mode&&n.mode.kind==="schottky"){n.mode.cur=[...M(a),0],w={disk:!0,panel:r,view:o.view};return}const l=!e.altKey&&Ue(t,s,o.view);if(l){const u=ce()&&n.at?n.at.time:0;w={handle:l,time:u,base:JSON.parse(JSON.stringify(n.recipe)),moved:!1,panel:r,view:o.view};return}if(e.altKey){n.pins=[n.pins[1],M(a)],ze(),N();return}if(o.view==="sphere"&&!e.shiftKey)return void c();w={from:M(a),base:JSON.parse(JSON.stringify(n.recipe)),moved:!1,panel:r,view:o.view}});function Ae(e,t){return{mobius:{from:[e,...n.pins],to:[M(t),...n.pins]}}}const Y=e=>{const[t,s]=ie(e,w.panel);return Q(t,s,w.view)};window.addEventListener("mousemove",e=>{if(w){if(w.look){const t=n.look[2]/(E.getBoundingClientRect().width/O().length);n.look[0]=w.start[0]+(e.clientX-w.x)*t,n.look[1]=Math.max(-89.9,Math.min(89.9,w.start[1]+(e.clientY-w.y)*t)),T();return}if(w.disk){n.mode.cur[2]=M([ae(n.mode.cur,Y(e))])[0],N();return}if(w.moved=!0,w.handle){n.recipe=ge(w.base,w.handle,Y(e),w.time),$();return}n.recipe={...w.base,steps:[...w.base.steps,Ae(w.from,Y(e))]},$()}});window.addEventListener("mouseup",e=>{if(!w)return;const t=w,s=t.look?null:Y(e);if(w=null,t.disk){const r=[...n.mode.cur.slice(0,2),M([ae(n.mode.cur,s)])[0]];return r[2]>=.5&&r[2]<90?void Ve(r):(n.mode.cur=null,N(),v("Schottky disks: drag out a radius (0.5 to 90 degrees) from the centre",!0))}if(!(t.look||!t.moved)){if(t.handle)return void We(t,s);n.undo.push(JSON.stringify(t.base)),n.redo=[],n.recipe={...t.base,steps:[...t.base.steps,Ae(t.from,s)]},$(),H()}});async function We(e,t){const s=ge(e.base,e.handle,t,e.time);n.recipe=e.base;try{await F(`api/stages?t=${e.time}`,s)}catch(o){return $(),await window.spherewarp.settle(),v(`moving the mark: ${o.message}`,!0)}q(s),await window.spherewarp.settle();const r=JSON.stringify(ye(e.base,e.handle.path)).includes('"keyframes"');v((e.handle.radius?"disk radius changed":"mark moved")+(r?` (keyframe at t = ${e.time} s)`:""))}E.addEventListener("wheel",e=>{e.preventDefault();const[t,s,r]=ie(e),o=O()[r];if((e.ctrlKey||e.metaKey||e.altKey)&&o.edited){const a=M(Q(t,s,o.view)),c=Math.exp(-e.deltaY*.002),l=[...n.recipe.steps],u=l[l.length-1];u&&u.zoom&&u.zoom.at[0]===a[0]&&u.zoom.at[1]===a[1]&&!w?l[l.length-1]={zoom:{at:a,factor:u.zoom.factor*c}}:l.push({zoom:{at:a,factor:c}}),q({...n.recipe,steps:l})}else o.view==="sphere"?(n.look[2]=Math.max(10,Math.min(170,n.look[2]*Math.exp(e.deltaY*.001))),T()):o.view==="planet"&&(n.planet=Math.max(.05,Math.min(20,n.planet*Math.exp(e.deltaY*.001))),T())},{passive:!1});window.addEventListener("keydown",e=>{if(e.key==="Escape"&&n.mode)return K(null),v("cancelled");if(!(e.ctrlKey||e.metaKey))return;const t=e.target;if(!(t instanceof HTMLElement&&(t.isContentEditable||t.tagName==="TEXTAREA"||t.tagName==="INPUT"&&!["range","checkbox","button","file"].includes(t.type)))){if(e.key==="z"&&!e.shiftKey)be();else if(e.key==="y"||e.key==="z"&&e.shiftKey)Te();else return;e.preventDefault()}});function ze(){p("pins").textContent=n.pins.map(e=>`(${e[0].toFixed(1)}, ${e[1].toFixed(1)})`).join(" ")}function Ze(e,t){const s=Math.max(1,Math.abs(e))*2,r=t||{},o=r.integer?Math.max(1,Math.round(s/500)):s/500;let a=Math.round(s/o),c=a;const l=d=>Math.max(0,Math.floor(d/o-1e-6)),u=d=>Math.max(0,Math.ceil(d/o-1e-6)-1);return r.ge!=null&&(a=Math.min(a,l(e-r.ge))),r.gt!=null&&(a=Math.min(a,u(e-r.gt))),r.le!=null&&(c=Math.min(c,l(r.le-e))),r.lt!=null&&(c=Math.min(c,u(r.lt-e))),[e-a*o,e+c*o,o]}function H(){const e=p("params");e.replaceChildren(),n.recipe.steps.forEach((t,s)=>{const[r,o]=Object.entries(t)[0],a=document.createElement("fieldset"),c=document.createElement("legend");c.textContent=`${s+1}. ${r}`;const l=document.createElement("button");l.textContent="×",l.title="remove this step",l.onclick=()=>q({...n.recipe,steps:n.recipe.steps.filter((f,h)=>h!==s)}),c.append(" ",l),a.append(c);const u=(f,h,m,g)=>{const y=h(),[P,_,b]=Ze(y,g),D=document.createElement("label"),x=document.createElement("input");x.type="range",x.min=P,x.max=_,x.step=b,x.value=y;const A=document.createElement("span");A.textContent=(+y).toPrecision(5);let R=null,I=y;x.oninput=()=>{R===null&&(R=JSON.stringify(n.recipe)),g&&g.nonzero&&+x.value==0&&(x.value=I>0?-b:b),I=+x.value,m(+x.value),A.textContent=(+x.value).toPrecision(5),$()},x.onchange=()=>{R!==null&&(n.undo.push(R),n.redo=[]),R=null,H()},D.append(`${f} `,x,A),a.append(D)},d=(f,h)=>{for(const[m,g]of Object.entries(f))if(typeof g=="number"){const y=h?null:((n.params||{})[r]||{})[m];u(`${h}${m}`,()=>f[m],P=>f[m]=P,y)}else(Array.isArray(g)||g&&typeof g=="object"&&!g.keyframes)&&d(g,`${h}${m}.`)};d(o,""),e.append(a)})}function Qe(e,t){const s=document.createElement("a");s.href=URL.createObjectURL(t),s.download=e,s.click()}function et(){const e=JSON.stringify(n.recipe,null,1),[t,s]=n.size,r=n.recipe.view,o=r&&typeof r=="object"&&Object.keys(r).length?"":` --size ${t}x${s}`,a=n.video?`spherewarp video ${n.imageName} -o out.mp4${o} recipe recipe.json`:`spherewarp render recipe.json ${n.imageName} -o out.png${o}`;return`cat > recipe.json <<'EOF'
${e}
EOF
${a}`}function tt(){p("undo").onclick=be,p("redo").onclick=Te,p("save").onclick=()=>Qe("recipe.json",new Blob([JSON.stringify(n.recipe,null,2)+`
`],{type:"application/json"})),p("load-button").onclick=()=>p("load").click(),p("load").onchange=async e=>{const t=e.target.files[0];if(t){e.target.value="";try{const s=JSON.parse(await t.text());await F("api/stages",s),q(s)}catch(s){v(`${t.name}: ${s.message}`,!0)}}},p("copy").onclick=async()=>{const e=et();p("cli").value=e;try{await navigator.clipboard.writeText(e),v("copied the command")}catch{v("the command is in the box below (the clipboard is not available)")}},p("render").onclick=async()=>{const e=p("render");if(e.disabled)return;e.disabled=!0;const t=(s,r=!1)=>{e.disabled=!1,v(s,r)};try{const s=n.video?`?t=${Ee()}`:"",{job:r}=await F(`api/render${s}`,n.recipe),o=async()=>{let a;try{const l=await fetch(`api/render/${r}`);if(a=await l.json(),!l.ok)throw new Error(a.error||`HTTP ${l.status}`)}catch(l){return t(`render: no answer from the server about the render (${l.message})`,!0)}if(a.error)return t(`render: ${a.error}`,!0);if(!a.done)return v(a.started?`rendering ${(100*a.progress).toFixed(0)}%`:"waiting for an earlier render"),setTimeout(o,300);t("rendered: downloading");const c=document.createElement("a");c.href=`api/render/${r}/file`,c.download="",c.click()};o()}catch(s){t(`render: ${s.message}`,!0)}};for(const e of["flat","sphere","planet"])p(`v-${e}`).onclick=()=>{n.view=e,G(),T()};p("side").onchange=()=>{n.side=p("side").value||null;const[e]=Pe();n.size[0]>e&&(n.size=[e,Math.max(1,Math.round(n.size[1]*e/n.size[0]))],p("size").value=`${n.size[0]}x${n.size[1]}`,v(`size ${n.size[0]}x${n.size[1]}: the panels side by side are as wide as this GPU draws`)),G(),T()},p("show-marks").checked=n.marks,p("show-marks").onchange=()=>{n.marks=p("show-marks").checked,G(),N()},p("m-droste").onclick=()=>K("droste"),p("m-schottky").onclick=()=>K("schottky"),p("overlay").oninput=async()=>{if(!n.patternLoaded){n.patternLoaded=!0;const e=new Image;e.src="testpattern",await e.decode(),U(e,2)}n.overlay=+p("overlay").value,T()},p("size").onchange=()=>Be(p("size").value)}async function nt(){const e=await(await fetch("api/state")).json();n.imageName=e.image.name,n.rate=e.rate,n.stageNames=Object.fromEntries(e.table.stages.map(r=>[r.code,r.name])),n.params=e.params,n.recipe=e.recipe;const t=e.image.width/e.image.height;n.size=[Math.min(e.image.width,2048),Math.round(Math.min(e.image.width,2048)/t)],Ye(),p("size").value=`${n.size[0]}x${n.size[1]}`,p("side").value=n.side||"",$e(e.glsl_header);const s=new Image;s.src="image",await s.decode(),U(s),U(s,2),e.image.video&&await Ne(),tt(),ze(),H(),$()}window.spherewarp={S:n,draw:T,pixelToLonLat:Q,lonLatToPixel:z,markPositions:Ge,setRecipe:e=>q(e),setStages:async e=>{await ve(e),T()},seek:e=>new Promise(t=>{const s=n.video;s.pause();const r=()=>{if(s.seeking||n.videoTime!==s.currentTime)return requestAnimationFrame(r);window.spherewarp.settle().then(()=>t(s.currentTime))};s.addEventListener("seeked",()=>requestAnimationFrame(r),{once:!0}),s.currentTime=e}),settle:()=>new Promise(e=>{if(!Z&&!X)return e();window.addEventListener("sw-drawn",()=>e(),{once:!0})}),frameTime:e=>{const t=new Uint8Array(4),s=performance.now();for(let r=0;r<e;r++)T(),i.readPixels(0,0,1,1,i.RGBA,i.UNSIGNED_BYTE,t);return(performance.now()-s)/e}};nt().then(()=>window.spherewarp.ready=!0).catch(e=>{v(e.message,!0),window.spherewarp.error=e.message});
