(function(){const o=document.createElement("link").relList;if(o&&o.supports&&o.supports("modulepreload"))return;for(const i of document.querySelectorAll('link[rel="modulepreload"]'))a(i);new MutationObserver(i=>{for(const r of i)if(r.type==="childList")for(const c of r.addedNodes)c.tagName==="LINK"&&c.rel==="modulepreload"&&a(c)}).observe(document,{childList:!0,subtree:!0});function s(i){const r={};return i.integrity&&(r.integrity=i.integrity),i.referrerPolicy&&(r.referrerPolicy=i.referrerPolicy),i.crossOrigin==="use-credentials"?r.credentials="include":i.crossOrigin==="anonymous"?r.credentials="omit":r.credentials="same-origin",r}function a(i){if(i.ep)return;i.ep=!0;const r=s(i);fetch(i.href,r)}})();const B=`#version 300 es
in vec2 pos;
void main() { gl_Position = vec4(pos, 0.0, 1.0); }
`,K=`
uniform sampler2D uImage;   // the panorama, mipmapped, RGBA8
uniform highp sampler2D uParams;  // R32F: row s = stage s's parameter row
uniform int uCodes[MAX_STAGES];
uniform int uCount;          // number of stages; -1: the map has none (show a pattern)
uniform int uView;           // 0 flat, 1 sphere, 2 little planet
uniform vec2 uSize;          // the canvas in pixels
uniform vec3 uLook;          // yaw, pitch (radians), field of view (radians, horizontal)
uniform float uPlanet;       // little planet: scale of the plane
uniform int uSS;             // sub-samples per pixel along each axis (1 to 4)
out vec4 color;

const float PI = 3.14159265358979;

uniform vec4 uPV[PV_SIZE];   // the rows again, packed 4 floats a vec4, when they fit
uniform int uBase[MAX_STAGES];  // where row s starts in uPV (in floats)
uniform bool uUniformRows;   // read uPV (a uniform read is much cheaper than texelFetch)

float P(int s, int i) {
  if (uUniformRows) {
    int k = uBase[s] + i;
    return uPV[k >> 2][k & 3];
  }
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

vec4 stageMobius(int s, vec4 v) {
  mat4 L;  // row-major in the row: L[col][row] in GLSL
  for (int i = 0; i < 4; i++)
    for (int j = 0; j < 4; j++) L[j][i] = P(s, MOBIUS_L00 + 4 * i + j);
  return L * v;
}

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
    int o = SCHOTTKY_MOVES + move * SCHOTTKY_MOVES_SIZE + SCHOTTKY_MOVES_L00;
    mat4 L;
    for (int i = 0; i < 4; i++)
      for (int k = 0; k < 4; k++) L[k][i] = P(s, o + 4 * i + k);
    v = L * v;
    v /= v.x;
    last = move;
  }
  return vec4(-1.0, 0.0, 0.0, 0.0);
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
  vec4 c = textureGrad(uImage, uv, lonlatGrad(s, dx), lonlatGrad(s, dy));
  return v.x < 0.0 ? vec4(0.0, 0.0, 0.0, 1.0) : vec4(c.rgb, 1.0);
}

void main() {
  vec2 p = vec2(gl_FragCoord.x, uSize.y - gl_FragCoord.y);
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
`,k=32,j=256,P=Math.PI/180,p=e=>document.getElementById(e),x=p("view"),v=(e,o=!1)=>{p("status").textContent=e,p("status").className=o?"bad":""},n={recipe:{spherewarp:1,steps:[]},view:"flat",size:[1024,512],look:[0,0,90],planet:1,pins:[[0,90],[0,-90]],undo:[],redo:[],stages:null,image:null,frames:0,ss:2},t=x.getContext("webgl2",{preserveDrawingBuffer:!0,antialias:!1});let S=null,E={},U=null;function Y(e){const o=`#version 300 es
precision highp float;
precision highp int;
#define MAX_STAGES ${k}
#define PV_SIZE ${j}
${e}
${K}`,s=(r,c)=>{const u=t.createShader(r);if(t.shaderSource(u,c),t.compileShader(u),!t.getShaderParameter(u,t.COMPILE_STATUS))throw new Error(t.getShaderInfoLog(u));return u};if(S=t.createProgram(),t.attachShader(S,s(t.VERTEX_SHADER,B)),t.attachShader(S,s(t.FRAGMENT_SHADER,o)),t.linkProgram(S),!t.getProgramParameter(S,t.LINK_STATUS))throw new Error(t.getProgramInfoLog(S));t.useProgram(S);for(const r of["uImage","uParams","uCodes","uCount","uView","uSize","uLook","uPlanet","uSS","uPV","uBase","uUniformRows"])E[r]=t.getUniformLocation(S,r);const a=t.createBuffer();t.bindBuffer(t.ARRAY_BUFFER,a),t.bufferData(t.ARRAY_BUFFER,new Float32Array([-1,-1,3,-1,-1,3]),t.STATIC_DRAW);const i=t.getAttribLocation(S,"pos");t.enableVertexAttribArray(i),t.vertexAttribPointer(i,2,t.FLOAT,!1,0,0)}function H(e){const o=t.createTexture();t.activeTexture(t.TEXTURE0),t.bindTexture(t.TEXTURE_2D,o),t.pixelStorei(t.UNPACK_COLORSPACE_CONVERSION_WEBGL,t.NONE),t.pixelStorei(t.UNPACK_PREMULTIPLY_ALPHA_WEBGL,!1),t.texImage2D(t.TEXTURE_2D,0,t.RGBA8,t.RGBA,t.UNSIGNED_BYTE,e),t.generateMipmap(t.TEXTURE_2D),t.texParameteri(t.TEXTURE_2D,t.TEXTURE_MIN_FILTER,t.LINEAR_MIPMAP_LINEAR),t.texParameteri(t.TEXTURE_2D,t.TEXTURE_MAG_FILTER,t.LINEAR),t.texParameteri(t.TEXTURE_2D,t.TEXTURE_WRAP_S,t.REPEAT),t.texParameteri(t.TEXTURE_2D,t.TEXTURE_WRAP_T,t.CLAMP_TO_EDGE),t.uniform1i(E.uImage,0)}const J=["mobius","power","exp","rational","droste","schottky"];function X(e){if(n.stages=e,e.codes===null){v(`no live preview: ${e.missing}`,!0);return}const o=e.codes.map(c=>n.stageNames[c]).filter(c=>!J.includes(c));if(o.length){v(`no live preview: the shader has no '${o[0]}' stage yet (render full resolution)`,!0),n.stages={codes:null};return}if(e.codes.length>k){v(`no live preview: ${e.codes.length} stages (the shader takes ${k})`,!0),n.stages={codes:null};return}const s=Math.max(...e.rows.map(c=>c.length)),a=new Float32Array(s*e.rows.length);e.rows.forEach((c,u)=>a.set(c,u*s)),U||(U=t.createTexture()),t.activeTexture(t.TEXTURE1),t.bindTexture(t.TEXTURE_2D,U),t.pixelStorei(t.UNPACK_ALIGNMENT,1),t.texImage2D(t.TEXTURE_2D,0,t.R32F,s,e.rows.length,0,t.RED,t.FLOAT,a),t.texParameteri(t.TEXTURE_2D,t.TEXTURE_MIN_FILTER,t.NEAREST),t.texParameteri(t.TEXTURE_2D,t.TEXTURE_MAG_FILTER,t.NEAREST),t.uniform1i(E.uParams,1);const i=new Int32Array(k);i.set(e.codes),t.uniform1iv(E.uCodes,i);const r=a.length<=4*j;if(t.uniform1i(E.uUniformRows,r?1:0),r){const c=new Float32Array(4*j);c.set(a);const u=new Int32Array(k);e.rows.forEach((z,h)=>u[h]=h*s),t.uniform4fv(E.uPV,c),t.uniform1iv(E.uBase,u)}}function T(){const[e,o]=n.size;(x.width!==e||x.height!==o)&&(x.width=e,x.height=o),t.viewport(0,0,e,o),t.uniform1i(E.uCount,n.stages&&n.stages.codes?n.stages.codes.length:-1),t.uniform1i(E.uView,{flat:0,sphere:1,planet:2}[n.view]),t.uniform2f(E.uSize,e,o),t.uniform3f(E.uLook,n.look[0]*P,n.look[1]*P,n.look[2]*P),t.uniform1f(E.uPlanet,n.planet),t.uniform1i(E.uSS,n.ss),t.drawArrays(t.TRIANGLES,0,3),n.frames+=1}function M(e,o){const[s,a]=n.size;if(n.view==="flat")return[e/s*360-180,90-o/a*180];const i=(2*e-s)/s,r=(2*o-a)/s;let c;if(n.view==="sphere"){const[h,f,w]=n.look.map(O=>O*P),g=Math.cos(h),l=Math.sin(h),y=Math.cos(f),R=Math.sin(f),d=Math.tan(w/2);c=[y*g-d*i*l+d*r*R*g,y*l+d*i*g+d*r*R*l,R-d*r*y]}else{let h=i*n.planet,f=r*n.planet;const w=Math.cos(n.look[0]*P),g=Math.sin(n.look[0]*P);[h,f]=[w*h-g*f,g*h+w*f];const l=h*h+f*f;c=[2*h/(1+l),-2*f/(1+l),(l-1)/(1+l)]}const u=Math.atan2(c[1],c[0])/P,z=Math.atan2(c[2],Math.hypot(c[0],c[1]))/P;return[u,z]}function C(e){const o=x.getBoundingClientRect();return[(e.clientX-o.left)*n.size[0]/o.width,(e.clientY-o.top)*n.size[1]/o.height]}const I=e=>e.map(o=>Math.round(o*1e6)/1e6);let L=null,N=!1;async function $(e,o){const s=await fetch(e,{method:"POST",headers:{"Content-Type":"application/json"},body:JSON.stringify(o)}),a=await s.json();if(!s.ok)throw new Error(a.error||`HTTP ${s.status}`);return a}function _(){L=JSON.parse(JSON.stringify(n.recipe)),N||W(),q()}async function W(){for(N=!0;L;){const e=L;L=null;try{const{stages:o}=await $("api/stages",e);X(o),o.codes&&v(`${e.steps.length} step(s), ${o.codes.length} stage(s)`)}catch(o){v(o.message,!0)}T()}N=!1,n.settled=!0,window.dispatchEvent(new Event("sw-drawn"))}function D(e){n.undo.push(JSON.stringify(n.recipe)),n.redo=[],n.recipe=e,_(),b()}function G(){n.undo.length&&(n.redo.push(JSON.stringify(n.recipe)),n.recipe=JSON.parse(n.undo.pop()),_(),b())}function F(){n.redo.length&&(n.undo.push(JSON.stringify(n.recipe)),n.recipe=JSON.parse(n.redo.pop()),_(),b())}function q(){const e=new URLSearchParams;e.set("view",n.view),e.set("size",`${n.size[0]}x${n.size[1]}`),n.ss!==2&&e.set("ss",n.ss),e.set("recipe",JSON.stringify(n.recipe)),history.replaceState(null,"",`?${e}`)}function Z(){const e=new URLSearchParams(location.search);["flat","sphere","planet"].includes(e.get("view"))&&(n.view=e.get("view"));const o=/^(\d+)x(\d+)$/.exec(e.get("size")||"");o&&(n.size=[Math.min(+o[1],8192),Math.min(+o[2],8192)]);const s=+e.get("ss");if(s>=1&&s<=4&&(n.ss=Math.round(s)),e.get("recipe"))try{n.recipe=JSON.parse(e.get("recipe"))}catch(a){v(`recipe in the URL: ${a.message}`,!0)}}let m=null;x.addEventListener("mousedown",e=>{e.preventDefault();const[o,s]=C(e),a=M(o,s);if(e.altKey){n.pins=[n.pins[1],I(a)],V();return}if(n.view==="sphere"&&!e.shiftKey){m={look:!0,x:e.clientX,y:e.clientY,start:[...n.look]};return}m={from:I(a),base:JSON.parse(JSON.stringify(n.recipe)),moved:!1}});function Q(e){return{mobius:{from:[m.from,...n.pins],to:[I(e),...n.pins]}}}window.addEventListener("mousemove",e=>{if(!m)return;if(m.look){const s=n.look[2]/x.getBoundingClientRect().width;n.look[0]=m.start[0]+(e.clientX-m.x)*s,n.look[1]=Math.max(-89.9,Math.min(89.9,m.start[1]+(e.clientY-m.y)*s)),T();return}const o=M(...C(e));m.moved=!0,n.recipe={...m.base,steps:[...m.base.steps,Q(o)]},_()});window.addEventListener("mouseup",e=>{if(!m)return;const o=m;if(m=null,o.look||!o.moved)return;const s=M(...C(e));n.undo.push(JSON.stringify(o.base)),n.redo=[],n.recipe={...o.base,steps:[...o.base.steps,{mobius:{from:[o.from,...n.pins],to:[I(s),...n.pins]}}]},_(),b()});x.addEventListener("wheel",e=>{if(e.preventDefault(),e.ctrlKey||e.metaKey||e.altKey){const o=I(M(...C(e))),s=Math.exp(-e.deltaY*.002),a=[...n.recipe.steps],i=a[a.length-1];i&&i.zoom&&i.zoom.at[0]===o[0]&&i.zoom.at[1]===o[1]&&!m?a[a.length-1]={zoom:{at:o,factor:i.zoom.factor*s}}:a.push({zoom:{at:o,factor:s}}),D({...n.recipe,steps:a})}else n.view==="sphere"?(n.look[2]=Math.max(10,Math.min(170,n.look[2]*Math.exp(e.deltaY*.001))),T()):n.view==="planet"&&(n.planet=Math.max(.05,Math.min(20,n.planet*Math.exp(e.deltaY*.001))),T())},{passive:!1});window.addEventListener("keydown",e=>{if(e.ctrlKey||e.metaKey){if(e.key==="z"&&!e.shiftKey)G();else if(e.key==="y"||e.key==="z"&&e.shiftKey)F();else return;e.preventDefault()}});function V(){p("pins").textContent=n.pins.map(e=>`(${e[0].toFixed(1)}, ${e[1].toFixed(1)})`).join(" ")}function b(){const e=p("params");e.replaceChildren(),n.recipe.steps.forEach((o,s)=>{const[a,i]=Object.entries(o)[0],r=document.createElement("fieldset"),c=document.createElement("legend");c.textContent=`${s+1}. ${a}`;const u=document.createElement("button");u.textContent="×",u.title="remove this step",u.onclick=()=>D({...n.recipe,steps:n.recipe.steps.filter((f,w)=>w!==s)}),c.append(" ",u),r.append(c);const z=(f,w,g)=>{const l=w(),y=Math.max(1,Math.abs(l))*2,R=document.createElement("label"),d=document.createElement("input");d.type="range",d.min=l-y,d.max=l+y,d.step=y/500,d.value=l;const O=document.createElement("span");O.textContent=(+l).toPrecision(5);let A=null;d.oninput=()=>{A===null&&(A=JSON.stringify(n.recipe)),g(+d.value),O.textContent=(+d.value).toPrecision(5),_()},d.onchange=()=>{A!==null&&(n.undo.push(A),n.redo=[]),A=null,b()},R.append(`${f} `,d,O),r.append(R)},h=(f,w)=>{for(const[g,l]of Object.entries(f))typeof l=="number"?z(`${w}${g}`,()=>f[g],y=>f[g]=y):(Array.isArray(l)||l&&typeof l=="object"&&!l.keyframes)&&h(l,`${w}${g}.`)};h(i,""),e.append(r)})}function ee(e,o){const s=document.createElement("a");s.href=URL.createObjectURL(o),s.download=e,s.click()}function te(){const e=JSON.stringify(n.recipe,null,1),[o,s]=n.size;return`cat > recipe.json <<'EOF'
${e}
EOF
spherewarp render recipe.json ${n.imageName} -o out.png --size ${o}x${s}`}function ne(){p("undo").onclick=G,p("redo").onclick=F,p("save").onclick=()=>ee("recipe.json",new Blob([JSON.stringify(n.recipe,null,2)+`
`],{type:"application/json"})),p("load").onchange=async e=>{const o=e.target.files[0];if(o)try{const s=JSON.parse(await o.text());await $("api/stages",s),D(s)}catch(s){v(`${o.name}: ${s.message}`,!0)}},p("copy").onclick=async()=>{const e=te();p("cli").value=e;try{await navigator.clipboard.writeText(e),v("copied the command")}catch{v("the command is in the box below (the clipboard is not available)")}},p("render").onclick=async()=>{try{const{job:e}=await $("api/render",n.recipe),o=async()=>{const s=await(await fetch(`api/render/${e}`)).json();if(s.error)return v(`render: ${s.error}`,!0);if(!s.done)return v(`rendering ${(100*s.progress).toFixed(0)}%`),setTimeout(o,300);v("rendered: downloading");const a=document.createElement("a");a.href=`api/render/${e}/file`,a.download="",a.click()};o()}catch(e){v(e.message,!0)}};for(const e of["flat","sphere","planet"])p(`v-${e}`).onclick=()=>{n.view=e,q(),T()};p("size").onchange=()=>{const e=/^(\d+)x(\d+)$/.exec(p("size").value);e&&(n.size=[+e[1],+e[2]],q(),T())}}async function oe(){const e=await(await fetch("api/state")).json();n.imageName=e.image.name,n.stageNames=Object.fromEntries(e.table.stages.map(a=>[a.code,a.name])),n.recipe=e.recipe;const o=e.image.width/e.image.height;n.size=[Math.min(e.image.width,2048),Math.round(Math.min(e.image.width,2048)/o)],Z(),p("size").value=`${n.size[0]}x${n.size[1]}`,Y(e.glsl_header);const s=new Image;s.src="image",await s.decode(),H(s),ne(),V(),b(),_()}window.spherewarp={S:n,draw:T,pixelToLonLat:M,setRecipe:e=>D(e),setStages:e=>{X(e),T()},settle:()=>new Promise(e=>{if(!N&&!L)return e();window.addEventListener("sw-drawn",()=>e(),{once:!0})}),frameTime:e=>{const o=new Uint8Array(4),s=performance.now();for(let a=0;a<e;a++)T(),t.readPixels(0,0,1,1,t.RGBA,t.UNSIGNED_BYTE,o);return(performance.now()-s)/e}};oe().then(()=>window.spherewarp.ready=!0).catch(e=>{v(e.message,!0),window.spherewarp.error=e.message});
