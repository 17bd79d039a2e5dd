(function(){const o=document.createElement("link").relList;if(o&&o.supports&&o.supports("modulepreload"))return;for(const r of document.querySelectorAll('link[rel="modulepreload"]'))s(r);new MutationObserver(r=>{for(const i of r)if(i.type==="childList")for(const l of i.addedNodes)l.tagName==="LINK"&&l.rel==="modulepreload"&&s(l)}).observe(document,{childList:!0,subtree:!0});function a(r){const i={};return r.integrity&&(i.integrity=r.integrity),r.referrerPolicy&&(i.referrerPolicy=r.referrerPolicy),r.crossOrigin==="use-credentials"?i.credentials="include":r.crossOrigin==="anonymous"?i.credentials="omit":i.credentials="same-origin",i}function s(r){if(r.ep)return;r.ep=!0;const i=a(r);fetch(r.href,i)}})();const B=`#version 300 es
in vec2 pos;
void main() { gl_Position = vec4(pos, 0.0, 1.0); }
`,H=`
uniform sampler2D uImage;   // the panorama, mipmapped, RGBA8
uniform sampler2D uPattern; // the paper's test pattern, for the overlay
uniform float uOverlay;     // how much of the test pattern is mixed in (0: none)
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
  vec2 gx = lonlatGrad(s, dx), gy = lonlatGrad(s, dy);
  vec4 c = textureGrad(uImage, uv, gx, gy);
  if (uOverlay > 0.0) c = mix(c, textureGrad(uPattern, uv, gx, gy), uOverlay);
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
`,M=32,P=Math.PI/180,u=e=>document.getElementById(e),T=u("view"),m=(e,o=!1)=>{u("status").textContent=e,u("status").className=o?"bad":""},n={recipe:{spherewarp:1,steps:[]},view:"flat",size:[1024,512],look:[0,0,90],planet:1,pins:[[0,90],[0,-90]],undo:[],redo:[],stages:null,image:null,frames:0,overlay:0,ss:2},t=T.getContext("webgl2",{preserveDrawingBuffer:!0,antialias:!1});let S=null,y={},U=null;function V(e){const o=`#version 300 es
precision highp float;
precision highp int;
#define MAX_STAGES ${M}
${e}
${H}`,a=(i,l)=>{const h=t.createShader(i);if(t.shaderSource(h,l),t.compileShader(h),!t.getShaderParameter(h,t.COMPILE_STATUS))throw new Error(t.getShaderInfoLog(h));return h};if(S=t.createProgram(),t.attachShader(S,a(t.VERTEX_SHADER,B)),t.attachShader(S,a(t.FRAGMENT_SHADER,o)),t.linkProgram(S),!t.getProgramParameter(S,t.LINK_STATUS))throw new Error(t.getProgramInfoLog(S));t.useProgram(S);for(const i of["uImage","uParams","uCodes","uCount","uView","uSize","uLook","uPlanet","uSS","uPattern","uOverlay"])y[i]=t.getUniformLocation(S,i);const s=t.createBuffer();t.bindBuffer(t.ARRAY_BUFFER,s),t.bufferData(t.ARRAY_BUFFER,new Float32Array([-1,-1,3,-1,-1,3]),t.STATIC_DRAW);const r=t.getAttribLocation(S,"pos");t.enableVertexAttribArray(r),t.vertexAttribPointer(r,2,t.FLOAT,!1,0,0)}function j(e,o=0){const a=t.createTexture();t.activeTexture(t.TEXTURE0+o),t.bindTexture(t.TEXTURE_2D,a),t.pixelStorei(t.UNPACK_COLORSPACE_CONVERSION_WEBGL,t.NONE),t.pixelStorei(t.UNPACK_PREMULTIPLY_ALPHA_WEBGL,!1),t.texImage2D(t.TEXTURE_2D,0,t.RGBA8,t.RGBA,t.UNSIGNED_BYTE,e),t.generateMipmap(t.TEXTURE_2D),t.texParameteri(t.TEXTURE_2D,t.TEXTURE_MIN_FILTER,t.LINEAR_MIPMAP_LINEAR),t.texParameteri(t.TEXTURE_2D,t.TEXTURE_MAG_FILTER,t.LINEAR),t.texParameteri(t.TEXTURE_2D,t.TEXTURE_WRAP_S,t.REPEAT),t.texParameteri(t.TEXTURE_2D,t.TEXTURE_WRAP_T,t.CLAMP_TO_EDGE),t.uniform1i(o===0?y.uImage:y.uPattern,o)}const J=["mobius","power","exp","rational","droste","schottky"];function X(e){if(n.stages=e,e.codes===null){m(`no live preview: ${e.missing}`,!0);return}const o=e.codes.map(i=>n.stageNames[i]).filter(i=>!J.includes(i));if(o.length){m(`no live preview: the shader has no '${o[0]}' stage yet (render full resolution)`,!0),n.stages={codes:null};return}if(e.codes.length>M){m(`no live preview: ${e.codes.length} stages (the shader takes ${M})`,!0),n.stages={codes:null};return}const a=Math.max(...e.rows.map(i=>i.length)),s=new Float32Array(a*e.rows.length);e.rows.forEach((i,l)=>s.set(i,l*a)),U||(U=t.createTexture()),t.activeTexture(t.TEXTURE1),t.bindTexture(t.TEXTURE_2D,U),t.pixelStorei(t.UNPACK_ALIGNMENT,1),t.texImage2D(t.TEXTURE_2D,0,t.R32F,a,e.rows.length,0,t.RED,t.FLOAT,s),t.texParameteri(t.TEXTURE_2D,t.TEXTURE_MIN_FILTER,t.NEAREST),t.texParameteri(t.TEXTURE_2D,t.TEXTURE_MAG_FILTER,t.NEAREST),t.uniform1i(y.uParams,1);const r=new Int32Array(M);r.set(e.codes),t.uniform1iv(y.uCodes,r)}function w(){const[e,o]=n.size;(T.width!==e||T.height!==o)&&(T.width=e,T.height=o),t.viewport(0,0,e,o),t.uniform1i(y.uCount,n.stages&&n.stages.codes?n.stages.codes.length:-1),t.uniform1i(y.uView,{flat:0,sphere:1,planet:2}[n.view]),t.uniform2f(y.uSize,e,o),t.uniform3f(y.uLook,n.look[0]*P,n.look[1]*P,n.look[2]*P),t.uniform1f(y.uPlanet,n.planet),t.uniform1i(y.uSS,n.ss),t.uniform1f(y.uOverlay,n.overlay),t.drawArrays(t.TRIANGLES,0,3),n.frames+=1}function L(e,o){const[a,s]=n.size;if(n.view==="flat")return[e/a*360-180,90-o/s*180];const r=(2*e-a)/a,i=(2*o-s)/a;let l;if(n.view==="sphere"){const[g,f,E]=n.look.map(O=>O*P),v=Math.cos(g),c=Math.sin(g),x=Math.cos(f),_=Math.sin(f),d=Math.tan(E/2);l=[x*v-d*r*c+d*i*_*v,x*c+d*r*v+d*i*_*c,_-d*i*x]}else{let g=r*n.planet,f=i*n.planet;const E=Math.cos(n.look[0]*P),v=Math.sin(n.look[0]*P);[g,f]=[E*g-v*f,v*g+E*f];const c=g*g+f*f;l=[2*g/(1+c),-2*f/(1+c),(c-1)/(1+c)]}const h=Math.atan2(l[1],l[0])/P,D=Math.atan2(l[2],Math.hypot(l[0],l[1]))/P;return[h,D]}function N(e){const o=T.getBoundingClientRect();return[(e.clientX-o.left)*n.size[0]/o.width,(e.clientY-o.top)*n.size[1]/o.height]}const k=e=>e.map(o=>Math.round(o*1e6)/1e6);let A=null,z=!1;async function $(e,o){const a=await fetch(e,{method:"POST",headers:{"Content-Type":"application/json"},body:JSON.stringify(o)}),s=await a.json();if(!a.ok)throw new Error(s.error||`HTTP ${a.status}`);return s}function R(){A=JSON.parse(JSON.stringify(n.recipe)),z||W(),q()}async function W(){for(z=!0;A;){const e=A;A=null;try{const{stages:o}=await $("api/stages",e);X(o),o.codes&&m(`${e.steps.length} step(s), ${o.codes.length} stage(s)`)}catch(o){m(o.message,!0)}w()}z=!1,n.settled=!0,window.dispatchEvent(new Event("sw-drawn"))}function C(e){n.undo.push(JSON.stringify(n.recipe)),n.redo=[],n.recipe=e,R(),I()}function G(e,o){e.length&&(o.push(JSON.stringify(n.recipe)),n.recipe=JSON.parse(e.pop()),R(),I())}const F=()=>G(n.undo,n.redo),K=()=>G(n.redo,n.undo);function q(){const e=new URLSearchParams;e.set("view",n.view),e.set("size",`${n.size[0]}x${n.size[1]}`),n.ss!==2&&e.set("ss",n.ss),e.set("recipe",JSON.stringify(n.recipe)),history.replaceState(null,"",`?${e}`)}function Z(){const e=new URLSearchParams(location.search);["flat","sphere","planet"].includes(e.get("view"))&&(n.view=e.get("view"));const o=/^(\d+)x(\d+)$/.exec(e.get("size")||"");o&&(n.size=[Math.min(+o[1],8192),Math.min(+o[2],8192)]);const a=+e.get("ss");if(a>=1&&a<=4&&(n.ss=Math.round(a)),e.get("recipe"))try{n.recipe=JSON.parse(e.get("recipe"))}catch(s){m(`recipe in the URL: ${s.message}`,!0)}}let p=null;T.addEventListener("mousedown",e=>{e.preventDefault();const[o,a]=N(e),s=L(o,a);if(e.altKey){n.pins=[n.pins[1],k(s)],Y();return}if(n.view==="sphere"&&!e.shiftKey){p={look:!0,x:e.clientX,y:e.clientY,start:[...n.look]};return}p={from:k(s),base:JSON.parse(JSON.stringify(n.recipe)),moved:!1}});function Q(e){return{mobius:{from:[p.from,...n.pins],to:[k(e),...n.pins]}}}window.addEventListener("mousemove",e=>{if(!p)return;if(p.look){const a=n.look[2]/T.getBoundingClientRect().width;n.look[0]=p.start[0]+(e.clientX-p.x)*a,n.look[1]=Math.max(-89.9,Math.min(89.9,p.start[1]+(e.clientY-p.y)*a)),w();return}const o=L(...N(e));p.moved=!0,n.recipe={...p.base,steps:[...p.base.steps,Q(o)]},R()});window.addEventListener("mouseup",e=>{if(!p)return;const o=p;if(p=null,o.look||!o.moved)return;const a=L(...N(e));n.undo.push(JSON.stringify(o.base)),n.redo=[],n.recipe={...o.base,steps:[...o.base.steps,{mobius:{from:[o.from,...n.pins],to:[k(a),...n.pins]}}]},R(),I()});T.addEventListener("wheel",e=>{if(e.preventDefault(),e.ctrlKey||e.metaKey||e.altKey){const o=k(L(...N(e))),a=Math.exp(-e.deltaY*.002),s=[...n.recipe.steps],r=s[s.length-1];r&&r.zoom&&r.zoom.at[0]===o[0]&&r.zoom.at[1]===o[1]&&!p?s[s.length-1]={zoom:{at:o,factor:r.zoom.factor*a}}:s.push({zoom:{at:o,factor:a}}),C({...n.recipe,steps:s})}else n.view==="sphere"?(n.look[2]=Math.max(10,Math.min(170,n.look[2]*Math.exp(e.deltaY*.001))),w()):n.view==="planet"&&(n.planet=Math.max(.05,Math.min(20,n.planet*Math.exp(e.deltaY*.001))),w())},{passive:!1});window.addEventListener("keydown",e=>{if(e.ctrlKey||e.metaKey){if(e.key==="z"&&!e.shiftKey)F();else if(e.key==="y"||e.key==="z"&&e.shiftKey)K();else return;e.preventDefault()}});function Y(){u("pins").textContent=n.pins.map(e=>`(${e[0].toFixed(1)}, ${e[1].toFixed(1)})`).join(" ")}function I(){const e=u("params");e.replaceChildren(),n.recipe.steps.forEach((o,a)=>{const[s,r]=Object.entries(o)[0],i=document.createElement("fieldset"),l=document.createElement("legend");l.textContent=`${a+1}. ${s}`;const h=document.createElement("button");h.textContent="×",h.title="remove this step",h.onclick=()=>C({...n.recipe,steps:n.recipe.steps.filter((f,E)=>E!==a)}),l.append(" ",h),i.append(l);const D=(f,E,v)=>{const c=E(),x=Math.max(1,Math.abs(c))*2,_=document.createElement("label"),d=document.createElement("input");d.type="range",d.min=c-x,d.max=c+x,d.step=x/500,d.value=c;const O=document.createElement("span");O.textContent=(+c).toPrecision(5);let b=null;d.oninput=()=>{b===null&&(b=JSON.stringify(n.recipe)),v(+d.value),O.textContent=(+d.value).toPrecision(5),R()},d.onchange=()=>{b!==null&&(n.undo.push(b),n.redo=[]),b=null,I()},_.append(`${f} `,d,O),i.append(_)},g=(f,E)=>{for(const[v,c]of Object.entries(f))typeof c=="number"?D(`${E}${v}`,()=>f[v],x=>f[v]=x):(Array.isArray(c)||c&&typeof c=="object"&&!c.keyframes)&&g(c,`${E}${v}.`)};g(r,""),e.append(i)})}function ee(e,o){const a=document.createElement("a");a.href=URL.createObjectURL(o),a.download=e,a.click()}function te(){const e=JSON.stringify(n.recipe,null,1),[o,a]=n.size;return`cat > recipe.json <<'EOF'
${e}
EOF
spherewarp render recipe.json ${n.imageName} -o out.png --size ${o}x${a}`}function ne(){u("undo").onclick=F,u("redo").onclick=K,u("save").onclick=()=>ee("recipe.json",new Blob([JSON.stringify(n.recipe,null,2)+`
`],{type:"application/json"})),u("load").onchange=async e=>{const o=e.target.files[0];if(o)try{const a=JSON.parse(await o.text());await $("api/stages",a),C(a)}catch(a){m(`${o.name}: ${a.message}`,!0)}},u("copy").onclick=async()=>{const e=te();u("cli").value=e;try{await navigator.clipboard.writeText(e),m("copied the command")}catch{m("the command is in the box below (the clipboard is not available)")}},u("render").onclick=async()=>{try{const{job:e}=await $("api/render",n.recipe),o=async()=>{const a=await(await fetch(`api/render/${e}`)).json();if(a.error)return m(`render: ${a.error}`,!0);if(!a.done)return m(`rendering ${(100*a.progress).toFixed(0)}%`),setTimeout(o,300);m("rendered: downloading");const s=document.createElement("a");s.href=`api/render/${e}/file`,s.download="",s.click()};o()}catch(e){m(e.message,!0)}};for(const e of["flat","sphere","planet"])u(`v-${e}`).onclick=()=>{n.view=e,q(),w()};u("overlay").oninput=async()=>{if(!n.patternLoaded){n.patternLoaded=!0;const e=new Image;e.src="testpattern",await e.decode(),j(e,2)}n.overlay=+u("overlay").value,w()},u("size").onchange=()=>{const e=/^(\d+)x(\d+)$/.exec(u("size").value);e&&(n.size=[+e[1],+e[2]],q(),w())}}async function oe(){const e=await(await fetch("api/state")).json();n.imageName=e.image.name,n.stageNames=Object.fromEntries(e.table.stages.map(s=>[s.code,s.name])),n.recipe=e.recipe;const o=e.image.width/e.image.height;n.size=[Math.min(e.image.width,2048),Math.round(Math.min(e.image.width,2048)/o)],Z(),u("size").value=`${n.size[0]}x${n.size[1]}`,V(e.glsl_header);const a=new Image;a.src="image",await a.decode(),j(a),j(a,2),ne(),Y(),I(),R()}window.spherewarp={S:n,draw:w,pixelToLonLat:L,setRecipe:e=>C(e),setStages:e=>{X(e),w()},settle:()=>new Promise(e=>{if(!z&&!A)return e();window.addEventListener("sw-drawn",()=>e(),{once:!0})}),frameTime:e=>{const o=new Uint8Array(4),a=performance.now();for(let s=0;s<e;s++)w(),t.readPixels(0,0,1,1,t.RGBA,t.UNSIGNED_BYTE,o);return(performance.now()-a)/e}};oe().then(()=>window.spherewarp.ready=!0).catch(e=>{m(e.message,!0),window.spherewarp.error=e.message});
