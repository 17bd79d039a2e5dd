(function(){const n=document.createElement("link").relList;if(n&&n.supports&&n.supports("modulepreload"))return;for(const r of document.querySelectorAll('link[rel="modulepreload"]'))s(r);new MutationObserver(r=>{for(const c of r)if(c.type==="childList")for(const i of c.addedNodes)i.tagName==="LINK"&&i.rel==="modulepreload"&&s(i)}).observe(document,{childList:!0,subtree:!0});function o(r){const c={};return r.integrity&&(c.integrity=r.integrity),r.referrerPolicy&&(c.referrerPolicy=r.referrerPolicy),r.crossOrigin==="use-credentials"?c.credentials="include":r.crossOrigin==="anonymous"?c.credentials="omit":c.credentials="same-origin",c}function s(r){if(r.ep)return;r.ep=!0;const c=o(r);fetch(r.href,c)}})();const ye=`#version 300 es
in vec2 pos;
void main() { gl_Position = vec4(pos, 0.0, 1.0); }
`;function ge(e,n,o){let s=`vec2 exprEval(int slot, int s, vec2 z) {
`;for(let r=0;r<o;r++)s+=`  if (slot == ${r}) return expr${r}(s, z);
`;return s+=`  return z;
}
`,e.replace("//@EXPRESSIONS@",()=>`${n}
${s}`)}const xe=`
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
`,K=32,k=Math.PI/180,f=e=>document.getElementById(e),E=f("view"),M=f("marks"),y=(e,n=!1)=>{f("status").textContent=e,f("status").className=n?"bad":""},t={recipe:{spherewarp:1,steps:[]},view:"flat",side:null,mode:null,size:[1024,512],look:[0,0,90],planet:1,pins:[[0,90],[0,-90]],undo:[],redo:[],stages:null,image:null,frames:0,overlay:0,ss:2},a=E.getContext("webgl2",{preserveDrawingBuffer:!0,antialias:!1}),we=["uImage","uParams","uCodes","uCount","uView","uSize","uLook","uPlanet","uSS","uPattern","uOverlay","uLabels","uOrigin"];let S={},Y=null,V=null,te="";const G=new Map;let Q=null;function ne(e,n){const o=`${n}
${e}`;if(Q===o)return;let s=G.get(o);if(!s){if(!/^[A-Za-z0-9_\s(){},;=+\-*]*$/.test(e))throw new Error("unexpected expression GLSL");const r=`#version 300 es
precision highp float;
precision highp int;
#define MAX_STAGES ${K}
${te}
${ge(xe,e,n)}`,c=(v,h)=>{const l=a.createShader(v);if(a.shaderSource(l,h),a.compileShader(l),!a.getShaderParameter(l,a.COMPILE_STATUS))throw new Error(a.getShaderInfoLog(l));return l},i=a.createProgram();if(a.attachShader(i,c(a.VERTEX_SHADER,ye)),a.attachShader(i,c(a.FRAGMENT_SHADER,r)),a.bindAttribLocation(i,0,"pos"),a.linkProgram(i),!a.getProgramParameter(i,a.LINK_STATUS))throw new Error(a.getProgramInfoLog(i));const u={};for(const v of we)u[v]=a.getUniformLocation(i,v);s={prog:i,uni:u},G.size>16&&G.clear(),G.set(o,s)}a.useProgram(s.prog),S=s.uni,Q=o}function ke(e){te=e,ne("",0);const n=a.createBuffer();a.bindBuffer(a.ARRAY_BUFFER,n),a.bufferData(a.ARRAY_BUFFER,new Float32Array([-1,-1,3,-1,-1,3]),a.STATIC_DRAW),a.enableVertexAttribArray(0),a.vertexAttribPointer(0,2,a.FLOAT,!1,0,0)}function $(e,n=0,o=null){return o=o||a.createTexture(),a.activeTexture(a.TEXTURE0+n),a.bindTexture(a.TEXTURE_2D,o),a.pixelStorei(a.UNPACK_COLORSPACE_CONVERSION_WEBGL,a.NONE),a.pixelStorei(a.UNPACK_PREMULTIPLY_ALPHA_WEBGL,!1),a.texImage2D(a.TEXTURE_2D,0,a.RGBA8,a.RGBA,a.UNSIGNED_BYTE,e),a.generateMipmap(a.TEXTURE_2D),a.texParameteri(a.TEXTURE_2D,a.TEXTURE_MIN_FILTER,a.LINEAR_MIPMAP_LINEAR),a.texParameteri(a.TEXTURE_2D,a.TEXTURE_MAG_FILTER,a.LINEAR),a.texParameteri(a.TEXTURE_2D,a.TEXTURE_WRAP_S,a.REPEAT),a.texParameteri(a.TEXTURE_2D,a.TEXTURE_WRAP_T,a.CLAMP_TO_EDGE),o}let oe=null;function ee(){const e=t.video;e.readyState<2||(t.videoTime=e.currentTime,$(e,0,oe),b(),_e()&&ce(),f("vtime").textContent=`${e.currentTime.toFixed(2)} s`,!t.seeking&&e.duration&&(f("vseek").value=e.currentTime/e.duration))}async function Ee(){const e=document.createElement("video");e.muted=!0,e.loop=!0,e.playsInline=!0,e.preload="auto";const n=new Promise((s,r)=>{e.addEventListener("loadeddata",s,{once:!0}),e.addEventListener("error",()=>r(new Error(`video: ${e.error?e.error.message||`error ${e.error.code}`:"cannot play"} (the browser may lack its codec)`)),{once:!0})});e.src="video",await n,t.video=e,oe=$(e,0);const o=()=>{e.currentTime!==t.videoTime&&!e.seeking&&ee(),requestAnimationFrame(o)};requestAnimationFrame(o),e.addEventListener("seeked",ee),f("vctl").hidden=!1,f("play").onclick=()=>e.paused?e.play():e.pause(),e.addEventListener("play",()=>f("play").textContent="Pause"),e.addEventListener("pause",()=>f("play").textContent="Play"),f("vseek").oninput=()=>{t.seeking=!0,e.currentTime=+f("vseek").value*(e.duration||0)},f("vseek").onchange=()=>t.seeking=!1,e.play().catch(()=>f("play").textContent="Play")}const Se=["mobius","power","exp","rational","droste","schottky","schottky_mask","expression"];function se(e,n,o,s,r){a.activeTexture(a.TEXTURE0+n),a.bindTexture(a.TEXTURE_2D,e),a.pixelStorei(a.UNPACK_ALIGNMENT,1),a.texImage2D(a.TEXTURE_2D,0,a.R32F,o,s,0,a.RED,a.FLOAT,r),a.texParameteri(a.TEXTURE_2D,a.TEXTURE_MIN_FILTER,a.NEAREST),a.texParameteri(a.TEXTURE_2D,a.TEXTURE_MAG_FILTER,a.NEAREST)}async function Te(e){if(t.labelsKey===e.key)return;const n=await fetch(`api/labels/${e.key}`);if(!n.ok)throw new Error(`labels: HTTP ${n.status}`);const o=new Int16Array(await n.arrayBuffer());V||(V=a.createTexture()),se(V,3,e.width,e.height,Float32Array.from(o)),t.labelsKey=e.key}async function ae(e){if(t.stages={codes:null},e.codes===null){y(`no live preview: ${e.missing}`,!0);return}const n=e.codes.map(i=>t.stageNames[i]).filter(i=>!Se.includes(i));if(n.length){y(`no live preview: the shader has no '${n[0]}' stage yet (render full resolution)`,!0);return}if(e.codes.length>K){y(`no live preview: ${e.codes.length} stages (the shader takes ${K})`,!0);return}const o=e.labels||[];if(o.length>1){y("no live preview: the shader takes one masked Schottky group",!0);return}const s=e.codes.filter(i=>t.stageNames[i]==="expression").length;try{ne(e.glsl||"",s),o.length&&await Te(o[0])}catch(i){y(`no live preview: ${i.message}`,!0);return}const r=Math.max(1,...e.rows.map(i=>i.length)),c=new Float32Array(r*Math.max(1,e.rows.length));e.rows.forEach((i,u)=>c.set(i,u*r)),Y||(Y=a.createTexture()),se(Y,1,r,Math.max(1,e.rows.length),c),t.stages=e}function I(){const e={view:t.view,edited:!0};return t.side?t.side==="original"?[e,{view:t.view,edited:!1}]:[e,{view:t.side,edited:!0}]:[e]}function b(){const[e,n]=t.size,o=I();(E.width!==e*o.length||E.height!==n)&&(E.width=e*o.length,E.height=n);const s=new Int32Array(K);t.stages&&t.stages.codes&&s.set(t.stages.codes),a.uniform1iv(S.uCodes,s),a.uniform1i(S.uImage,0),a.uniform1i(S.uParams,1),a.uniform1i(S.uPattern,2),a.uniform1i(S.uLabels,3),a.uniform2f(S.uSize,e,n),a.uniform3f(S.uLook,t.look[0]*k,t.look[1]*k,t.look[2]*k),a.uniform1f(S.uPlanet,t.planet),a.uniform1i(S.uSS,t.ss),a.uniform1f(S.uOverlay,t.overlay);const r=t.stages&&t.stages.codes?t.stages.codes.length:-1;o.forEach((c,i)=>{a.viewport(i*e,0,e,n),a.uniform2f(S.uOrigin,i*e,0),a.uniform1i(S.uCount,c.edited?r:0),a.uniform1i(S.uView,{flat:0,sphere:1,planet:2}[c.view]),a.drawArrays(a.TRIANGLES,0,3)}),t.frames+=1,R()}function R(){const[e,n]=t.size,o=I();(M.width!==E.width||M.height!==E.height)&&(M.width=E.width,M.height=E.height);const s=M.getContext("2d");s.clearRect(0,0,M.width,M.height);const r=(i,u,v,h=5)=>{s.beginPath(),s.arc(i,u,h,0,2*Math.PI),s.lineWidth=3,s.strokeStyle="black",s.stroke(),s.lineWidth=1.5,s.strokeStyle=v,s.stroke()},c=(i,u,v,h,l)=>{const d=l?[...i,i[0]]:i;s.lineWidth=1.5,s.strokeStyle=u,s.beginPath();let g=null;for(const p of d){const m=X(p[0],p[1],h);m&&g&&Math.abs(m[0]-g[0])<e/2?s.lineTo(v+m[0],m[1]):m&&s.moveTo(v+m[0],m[1]),g=m}s.stroke()};o.forEach((i,u)=>{const v=u*e;if(s.save(),s.beginPath(),s.rect(v,0,e,n),s.clip(),u>0&&(s.fillStyle="#1d1f21",s.fillRect(v,0,1,n)),i.edited){for(const l of t.pins){const d=X(l[0],l[1],i.view);d&&r(v+d[0],d[1],"#ffd54a")}const h=t.mode;h&&h.kind==="droste"&&(h.points.forEach(l=>{const d=X(l[0],l[1],i.view);d&&r(v+d[0],d[1],"#4ae3ff",4)}),h.points.length>1&&c(be(h.points),"#4ae3ff",v,i.view,!1)),h&&h.kind==="schottky"&&(h.cur?[...h.disks,h.cur]:h.disks).forEach((d,g)=>c(Pe(d),g%2?"#ff7a4a":"#7aff4a",v,i.view,!0))}s.restore()})}const A=e=>{const[n,o]=[e[0]*k,e[1]*k];return[Math.cos(o)*Math.cos(n),Math.cos(o)*Math.sin(n),Math.sin(o)]},re=e=>[Math.atan2(e[1],e[0])/k,Math.atan2(e[2],Math.hypot(e[0],e[1]))/k],ie=(e,n)=>{const[o,s]=[A(e),A(n)];return Math.acos(Math.max(-1,Math.min(1,o[0]*s[0]+o[1]*s[1]+o[2]*s[2])))/k};function be(e,n){const o=[],s=e.length-1;for(let r=0;r<s;r++){const[c,i]=[A(e[r]),A(e[(r+1)%e.length])];for(let u=0;u<=16;u++){const v=u/16;o.push(re(c.map((h,l)=>h*(1-v)+i[l]*v)))}}return o}function Pe(e){const n=A(e),o=Math.abs(n[2])<.9?[0,0,1]:[1,0,0],s=o[0]*n[0]+o[1]*n[1]+o[2]*n[2];let r=o.map((h,l)=>h-s*n[l]);const c=Math.hypot(...r);r=r.map(h=>h/c);const i=[n[1]*r[2]-n[2]*r[1],n[2]*r[0]-n[0]*r[2],n[0]*r[1]-n[1]*r[0]],u=e[2]*k,v=[];for(let h=0;h<72;h++){const l=2*Math.PI*h/72;v.push(re(n.map((d,g)=>Math.cos(u)*d+Math.sin(u)*(Math.cos(l)*r[g]+Math.sin(l)*i[g]))))}return v}function H(e,n,o=t.view){const[s,r]=t.size;if(o==="flat")return[e/s*360-180,90-n/r*180];const c=(2*e-s)/s,i=(2*n-r)/s;let u;if(o==="sphere"){const[l,d,g]=t.look.map(_=>_*k),p=Math.cos(l),m=Math.sin(l),P=Math.cos(d),w=Math.sin(d),T=Math.tan(g/2);u=[P*p-T*c*m+T*i*w*p,P*m+T*c*p+T*i*w*m,w-T*i*P]}else{let l=c*t.planet,d=i*t.planet;const g=Math.cos(t.look[0]*k),p=Math.sin(t.look[0]*k);[l,d]=[g*l-p*d,p*l+g*d];const m=l*l+d*d;u=[2*l/(1+m),-2*d/(1+m),(m-1)/(1+m)]}const v=Math.atan2(u[1],u[0])/k,h=Math.atan2(u[2],Math.hypot(u[0],u[1]))/k;return[v,h]}function X(e,n,o=t.view){const[s,r]=t.size;if(o==="flat")return[((e+180)%360+360)%360/360*s,(90-n)/180*r];const c=A([e,n]);let i,u;if(o==="sphere"){const[l,d,g]=t.look.map(N=>N*k),p=Math.cos(l),m=Math.sin(l),P=Math.cos(d),w=Math.sin(d),T=[P*p,P*m,w],_=[-m,p,0],me=[-w*p,-w*m,P],z=N=>N[0]*c[0]+N[1]*c[1]+N[2]*c[2],Z=Math.tan(g/2);if(z(T)<=1e-6)return null;i=z(_)/(Z*z(T)),u=-z(me)/(Z*z(T))}else{if(c[2]>1-1e-9)return null;const l=c[0]/(1-c[2]),d=-c[1]/(1-c[2]),g=Math.cos(t.look[0]*k),p=Math.sin(t.look[0]*k);i=(g*l+p*d)/t.planet,u=(-p*l+g*d)/t.planet}const v=(i+1)*s/2,h=(u*s+r)/2;return Math.abs(v)<1e5&&Math.abs(h)<1e5?[v,h]:null}function W(e,n=null){const o=E.getBoundingClientRect(),s=(e.clientX-o.left)*E.width/o.width,r=(e.clientY-o.top)*E.height/o.height,c=n??Math.max(0,Math.min(I().length-1,Math.floor(s/t.size[0])));return[s-c*t.size[0],r,c]}const O=e=>e.map(n=>Math.round(n*1e6)/1e6);let C=null,F=!1;async function B(e,n){const o=await fetch(e,{method:"POST",headers:{"Content-Type":"application/json"},body:JSON.stringify(n)}),s=await o.json();if(!o.ok)throw new Error(s.error||`HTTP ${o.status}`);return s}function L(){ce(),U()}function ce(){C=JSON.parse(JSON.stringify(t.recipe)),F||Oe()}function le(){if(!t.video)return 0;const e=t.video.currentTime;return t.rate?Math.floor(e*t.rate+1e-4)/t.rate:e}const _e=()=>JSON.stringify(t.recipe).includes('"keyframes"');async function Oe(){for(F=!0;C;){const e=C;C=null;try{const n=t.video?`?t=${le()}`:"",{stages:o}=await B(`api/stages${n}`,e);await ae(o),o.codes&&y(`${e.steps.length} step(s), ${o.codes.length} stage(s)`)}catch(n){y(n.message,!0)}b()}F=!1,t.settled=!0,window.dispatchEvent(new Event("sw-drawn"))}function j(e){t.undo.push(JSON.stringify(t.recipe)),t.redo=[],t.recipe=e,L(),q()}function ue(e,n){e.length&&(n.push(JSON.stringify(t.recipe)),t.recipe=JSON.parse(e.pop()),L(),q())}const de=()=>ue(t.undo,t.redo),fe=()=>ue(t.redo,t.undo);function U(){const e=new URLSearchParams;e.set("view",t.view),e.set("size",`${t.size[0]}x${t.size[1]}`),t.ss!==2&&e.set("ss",t.ss),t.side&&e.set("side",t.side),e.set("recipe",JSON.stringify(t.recipe)),history.replaceState(null,"",`?${e}`)}function Me(){const e=new URLSearchParams(location.search);["flat","sphere","planet"].includes(e.get("view"))&&(t.view=e.get("view"));const n=/^(\d+)x(\d+)$/.exec(e.get("size")||"");n&&(t.size=[Math.min(+n[1],8192),Math.min(+n[2],8192)]),["flat","sphere","planet","original"].includes(e.get("side"))&&(t.side=e.get("side"));const o=+e.get("ss");if(o>=1&&o<=4&&(t.ss=Math.round(o)),e.get("recipe"))try{t.recipe=JSON.parse(e.get("recipe"))}catch(s){y(`recipe in the URL: ${s.message}`,!0)}}let x=null;async function ve(e,n){try{await B("api/stages",e)}catch(o){return y(`${n}: ${o.message}`,!0),!1}return j(e),!0}function D(e){t.mode=e===null||t.mode&&t.mode.kind===e?null:{kind:e,points:[],disks:[],cur:null},f("m-droste").classList.toggle("on",!!t.mode&&t.mode.kind==="droste"),f("m-schottky").classList.toggle("on",!!t.mode&&t.mode.kind==="schottky"),t.mode&&t.mode.kind==="droste"&&y("Droste frame: click its four corners, in order round the frame"),t.mode&&t.mode.kind==="schottky"&&y("Schottky disks: press at a centre and drag out the radius, for D_x and then its target D_X"),R()}async function Re(e){const n=t.mode;if(n.points.push(O(e)),R(),n.points.length<4)return y(`Droste frame: corner ${n.points.length} of 4`);const o=n.points;D(null),await ve({...t.recipe,steps:[...t.recipe.steps,{droste:{frame:o}}]},"Droste frame")&&y("Droste frame added")}async function Ae(e){const n=t.mode;if(n.disks.push(e),n.cur=null,R(),n.disks.length<2)return y("Schottky disks: now the target disk D_X");const o={disk:n.disks[0],to:n.disks[1]};D(null);const s=[...t.recipe.steps],r=s[s.length-1];r&&r.schottky&&Array.isArray(r.schottky.generators)?s[s.length-1]={schottky:{...r.schottky,generators:[...r.schottky.generators,o]}}:s.push({schottky:{generators:[o]}}),await ve({...t.recipe,steps:s},"Schottky disks")&&y("Schottky generator added")}E.addEventListener("mousedown",e=>{e.preventDefault();const[n,o,s]=W(e),r=I()[s],c=H(n,o,r.view),i=()=>x={look:!0,x:e.clientX,y:e.clientY,start:[...t.look]};if(!r.edited){r.view==="sphere"?i():y("this panel is the image unedited: edit in the other one");return}if(t.mode&&t.mode.kind==="droste")return void Re(c);if(t.mode&&t.mode.kind==="schottky"){t.mode.cur=[...O(c),0],x={disk:!0,panel:s,view:r.view};return}if(e.altKey){t.pins=[t.pins[1],O(c)],pe(),R();return}if(r.view==="sphere"&&!e.shiftKey)return void i();x={from:O(c),base:JSON.parse(JSON.stringify(t.recipe)),moved:!1,panel:s,view:r.view}});function he(e,n){return{mobius:{from:[e,...t.pins],to:[O(n),...t.pins]}}}const J=e=>{const[n,o]=W(e,x.panel);return H(n,o,x.view)};window.addEventListener("mousemove",e=>{if(x){if(x.look){const n=t.look[2]/(E.getBoundingClientRect().width/I().length);t.look[0]=x.start[0]+(e.clientX-x.x)*n,t.look[1]=Math.max(-89.9,Math.min(89.9,x.start[1]+(e.clientY-x.y)*n)),b();return}if(x.disk){t.mode.cur[2]=O([ie(t.mode.cur,J(e))])[0],R();return}x.moved=!0,t.recipe={...x.base,steps:[...x.base.steps,he(x.from,J(e))]},L()}});window.addEventListener("mouseup",e=>{if(!x)return;const n=x,o=n.look?null:J(e);if(x=null,n.disk){const s=[...t.mode.cur.slice(0,2),O([ie(t.mode.cur,o)])[0]];return s[2]>=.5&&s[2]<90?void Ae(s):(t.mode.cur=null,R(),y("Schottky disks: drag out a radius (0.5 to 90 degrees) from the centre",!0))}n.look||!n.moved||(t.undo.push(JSON.stringify(n.base)),t.redo=[],t.recipe={...n.base,steps:[...n.base.steps,he(n.from,o)]},L(),q())});E.addEventListener("wheel",e=>{e.preventDefault();const[n,o,s]=W(e),r=I()[s];if((e.ctrlKey||e.metaKey||e.altKey)&&r.edited){const c=O(H(n,o,r.view)),i=Math.exp(-e.deltaY*.002),u=[...t.recipe.steps],v=u[u.length-1];v&&v.zoom&&v.zoom.at[0]===c[0]&&v.zoom.at[1]===c[1]&&!x?u[u.length-1]={zoom:{at:c,factor:v.zoom.factor*i}}:u.push({zoom:{at:c,factor:i}}),j({...t.recipe,steps:u})}else r.view==="sphere"?(t.look[2]=Math.max(10,Math.min(170,t.look[2]*Math.exp(e.deltaY*.001))),b()):r.view==="planet"&&(t.planet=Math.max(.05,Math.min(20,t.planet*Math.exp(e.deltaY*.001))),b())},{passive:!1});window.addEventListener("keydown",e=>{if(e.key==="Escape"&&t.mode)return D(null),y("cancelled");if(e.ctrlKey||e.metaKey){if(e.key==="z"&&!e.shiftKey)de();else if(e.key==="y"||e.key==="z"&&e.shiftKey)fe();else return;e.preventDefault()}});function pe(){f("pins").textContent=t.pins.map(e=>`(${e[0].toFixed(1)}, ${e[1].toFixed(1)})`).join(" ")}function q(){const e=f("params");e.replaceChildren(),t.recipe.steps.forEach((n,o)=>{const[s,r]=Object.entries(n)[0],c=document.createElement("fieldset"),i=document.createElement("legend");i.textContent=`${o+1}. ${s}`;const u=document.createElement("button");u.textContent="×",u.title="remove this step",u.onclick=()=>j({...t.recipe,steps:t.recipe.steps.filter((l,d)=>d!==o)}),i.append(" ",u),c.append(i);const v=(l,d,g)=>{const p=d(),m=Math.max(1,Math.abs(p))*2,P=document.createElement("label"),w=document.createElement("input");w.type="range",w.min=p-m,w.max=p+m,w.step=m/500,w.value=p;const T=document.createElement("span");T.textContent=(+p).toPrecision(5);let _=null;w.oninput=()=>{_===null&&(_=JSON.stringify(t.recipe)),g(+w.value),T.textContent=(+w.value).toPrecision(5),L()},w.onchange=()=>{_!==null&&(t.undo.push(_),t.redo=[]),_=null,q()},P.append(`${l} `,w,T),c.append(P)},h=(l,d)=>{for(const[g,p]of Object.entries(l))typeof p=="number"?v(`${d}${g}`,()=>l[g],m=>l[g]=m):(Array.isArray(p)||p&&typeof p=="object"&&!p.keyframes)&&h(p,`${d}${g}.`)};h(r,""),e.append(c)})}function Ie(e,n){const o=document.createElement("a");o.href=URL.createObjectURL(n),o.download=e,o.click()}function Le(){const e=JSON.stringify(t.recipe,null,1),[n,o]=t.size,s=t.video?`spherewarp video ${t.imageName} -o out.mp4 --size ${n}x${o} recipe recipe.json`:`spherewarp render recipe.json ${t.imageName} -o out.png --size ${n}x${o}`;return`cat > recipe.json <<'EOF'
${e}
EOF
${s}`}function ze(){f("undo").onclick=de,f("redo").onclick=fe,f("save").onclick=()=>Ie("recipe.json",new Blob([JSON.stringify(t.recipe,null,2)+`
`],{type:"application/json"})),f("load").onchange=async e=>{const n=e.target.files[0];if(n)try{const o=JSON.parse(await n.text());await B("api/stages",o),j(o)}catch(o){y(`${n.name}: ${o.message}`,!0)}},f("copy").onclick=async()=>{const e=Le();f("cli").value=e;try{await navigator.clipboard.writeText(e),y("copied the command")}catch{y("the command is in the box below (the clipboard is not available)")}},f("render").onclick=async()=>{try{const e=t.video?`?t=${le()}`:"",{job:n}=await B(`api/render${e}`,t.recipe),o=async()=>{const s=await(await fetch(`api/render/${n}`)).json();if(s.error)return y(`render: ${s.error}`,!0);if(!s.done)return y(`rendering ${(100*s.progress).toFixed(0)}%`),setTimeout(o,300);y("rendered: downloading");const r=document.createElement("a");r.href=`api/render/${n}/file`,r.download="",r.click()};o()}catch(e){y(e.message,!0)}};for(const e of["flat","sphere","planet"])f(`v-${e}`).onclick=()=>{t.view=e,U(),b()};f("side").onchange=()=>{t.side=f("side").value||null,U(),b()},f("m-droste").onclick=()=>D("droste"),f("m-schottky").onclick=()=>D("schottky"),f("overlay").oninput=async()=>{if(!t.patternLoaded){t.patternLoaded=!0;const e=new Image;e.src="testpattern",await e.decode(),$(e,2)}t.overlay=+f("overlay").value,b()},f("size").onchange=()=>{const e=/^(\d+)x(\d+)$/.exec(f("size").value);e&&(t.size=[+e[1],+e[2]],U(),b())}}async function Ne(){const e=await(await fetch("api/state")).json();t.imageName=e.image.name,t.rate=e.rate,t.stageNames=Object.fromEntries(e.table.stages.map(s=>[s.code,s.name])),t.recipe=e.recipe;const n=e.image.width/e.image.height;t.size=[Math.min(e.image.width,2048),Math.round(Math.min(e.image.width,2048)/n)],Me(),f("size").value=`${t.size[0]}x${t.size[1]}`,f("side").value=t.side||"",ke(e.glsl_header);const o=new Image;o.src="image",await o.decode(),$(o),$(o,2),e.image.video&&await Ee(),ze(),pe(),q(),L()}window.spherewarp={S:t,draw:b,pixelToLonLat:H,lonLatToPixel:X,setRecipe:e=>j(e),setStages:async e=>{await ae(e),b()},seek:e=>new Promise(n=>{const o=t.video;o.pause(),o.addEventListener("seeked",()=>window.spherewarp.settle().then(()=>n(o.currentTime)),{once:!0}),o.currentTime=e}),settle:()=>new Promise(e=>{if(!F&&!C)return e();window.addEventListener("sw-drawn",()=>e(),{once:!0})}),frameTime:e=>{const n=new Uint8Array(4),o=performance.now();for(let s=0;s<e;s++)b(),a.readPixels(0,0,1,1,a.RGBA,a.UNSIGNED_BYTE,n);return(performance.now()-o)/e}};Ne().then(()=>window.spherewarp.ready=!0).catch(e=>{y(e.message,!0),window.spherewarp.error=e.message});
