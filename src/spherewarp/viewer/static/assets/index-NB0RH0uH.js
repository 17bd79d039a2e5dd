(function(){const o=document.createElement("link").relList;if(o&&o.supports&&o.supports("modulepreload"))return;for(const i of document.querySelectorAll('link[rel="modulepreload"]'))s(i);new MutationObserver(i=>{for(const r of i)if(r.type==="childList")for(const l of r.addedNodes)l.tagName==="LINK"&&l.rel==="modulepreload"&&s(l)}).observe(document,{childList:!0,subtree:!0});function a(i){const r={};return i.integrity&&(r.integrity=i.integrity),i.referrerPolicy&&(r.referrerPolicy=i.referrerPolicy),i.crossOrigin==="use-credentials"?r.credentials="include":i.crossOrigin==="anonymous"?r.credentials="omit":r.credentials="same-origin",r}function s(i){if(i.ep)return;i.ep=!0;const r=a(i);fetch(i.href,r)}})();const K=`#version 300 es
in vec2 pos;
void main() { gl_Position = vec4(pos, 0.0, 1.0); }
`,Y=`
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

float P(int s, int i) { return texelFetch(uParams, ivec2(i, s), 0).r; }

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
`,M=32,P=Math.PI/180,d=e=>document.getElementById(e),x=d("view"),m=(e,o=!1)=>{d("status").textContent=e,d("status").className=o?"bad":""},t={recipe:{spherewarp:1,steps:[]},view:"flat",size:[1024,512],look:[0,0,90],planet:1,pins:[[0,90],[0,-90]],undo:[],redo:[],stages:null,image:null,frames:0,ss:2},n=x.getContext("webgl2",{preserveDrawingBuffer:!0,antialias:!1});let S=null,y={},U=null;function B(e){const o=`#version 300 es
precision highp float;
precision highp int;
#define MAX_STAGES ${M}
${e}
${Y}`,a=(r,l)=>{const v=n.createShader(r);if(n.shaderSource(v,l),n.compileShader(v),!n.getShaderParameter(v,n.COMPILE_STATUS))throw new Error(n.getShaderInfoLog(v));return v};if(S=n.createProgram(),n.attachShader(S,a(n.VERTEX_SHADER,K)),n.attachShader(S,a(n.FRAGMENT_SHADER,o)),n.linkProgram(S),!n.getProgramParameter(S,n.LINK_STATUS))throw new Error(n.getProgramInfoLog(S));n.useProgram(S);for(const r of["uImage","uParams","uCodes","uCount","uView","uSize","uLook","uPlanet","uSS"])y[r]=n.getUniformLocation(S,r);const s=n.createBuffer();n.bindBuffer(n.ARRAY_BUFFER,s),n.bufferData(n.ARRAY_BUFFER,new Float32Array([-1,-1,3,-1,-1,3]),n.STATIC_DRAW);const i=n.getAttribLocation(S,"pos");n.enableVertexAttribArray(i),n.vertexAttribPointer(i,2,n.FLOAT,!1,0,0)}function H(e){const o=n.createTexture();n.activeTexture(n.TEXTURE0),n.bindTexture(n.TEXTURE_2D,o),n.pixelStorei(n.UNPACK_COLORSPACE_CONVERSION_WEBGL,n.NONE),n.pixelStorei(n.UNPACK_PREMULTIPLY_ALPHA_WEBGL,!1),n.texImage2D(n.TEXTURE_2D,0,n.RGBA8,n.RGBA,n.UNSIGNED_BYTE,e),n.generateMipmap(n.TEXTURE_2D),n.texParameteri(n.TEXTURE_2D,n.TEXTURE_MIN_FILTER,n.LINEAR_MIPMAP_LINEAR),n.texParameteri(n.TEXTURE_2D,n.TEXTURE_MAG_FILTER,n.LINEAR),n.texParameteri(n.TEXTURE_2D,n.TEXTURE_WRAP_S,n.REPEAT),n.texParameteri(n.TEXTURE_2D,n.TEXTURE_WRAP_T,n.CLAMP_TO_EDGE),n.uniform1i(y.uImage,0)}const V=["mobius","power","exp","rational","droste","schottky"];function q(e){if(t.stages=e,e.codes===null){m(`no live preview: ${e.missing}`,!0);return}const o=e.codes.map(r=>t.stageNames[r]).filter(r=>!V.includes(r));if(o.length){m(`no live preview: the shader has no '${o[0]}' stage yet (render full resolution)`,!0),t.stages={codes:null};return}if(e.codes.length>M){m(`no live preview: ${e.codes.length} stages (the shader takes ${M})`,!0),t.stages={codes:null};return}const a=Math.max(...e.rows.map(r=>r.length)),s=new Float32Array(a*e.rows.length);e.rows.forEach((r,l)=>s.set(r,l*a)),U||(U=n.createTexture()),n.activeTexture(n.TEXTURE1),n.bindTexture(n.TEXTURE_2D,U),n.pixelStorei(n.UNPACK_ALIGNMENT,1),n.texImage2D(n.TEXTURE_2D,0,n.R32F,a,e.rows.length,0,n.RED,n.FLOAT,s),n.texParameteri(n.TEXTURE_2D,n.TEXTURE_MIN_FILTER,n.NEAREST),n.texParameteri(n.TEXTURE_2D,n.TEXTURE_MAG_FILTER,n.NEAREST),n.uniform1i(y.uParams,1);const i=new Int32Array(M);i.set(e.codes),n.uniform1iv(y.uCodes,i)}function T(){const[e,o]=t.size;(x.width!==e||x.height!==o)&&(x.width=e,x.height=o),n.viewport(0,0,e,o),n.uniform1i(y.uCount,t.stages&&t.stages.codes?t.stages.codes.length:-1),n.uniform1i(y.uView,{flat:0,sphere:1,planet:2}[t.view]),n.uniform2f(y.uSize,e,o),n.uniform3f(y.uLook,t.look[0]*P,t.look[1]*P,t.look[2]*P),n.uniform1f(y.uPlanet,t.planet),n.uniform1i(y.uSS,t.ss),n.drawArrays(n.TRIANGLES,0,3),t.frames+=1}function I(e,o){const[a,s]=t.size;if(t.view==="flat")return[e/a*360-180,90-o/s*180];const i=(2*e-a)/a,r=(2*o-s)/a;let l;if(t.view==="sphere"){const[g,f,E]=t.look.map(O=>O*P),h=Math.cos(g),c=Math.sin(g),w=Math.cos(f),R=Math.sin(f),u=Math.tan(E/2);l=[w*h-u*i*c+u*r*R*h,w*c+u*i*h+u*r*R*c,R-u*r*w]}else{let g=i*t.planet,f=r*t.planet;const E=Math.cos(t.look[0]*P),h=Math.sin(t.look[0]*P);[g,f]=[E*g-h*f,h*g+E*f];const c=g*g+f*f;l=[2*g/(1+c),-2*f/(1+c),(c-1)/(1+c)]}const v=Math.atan2(l[1],l[0])/P,D=Math.atan2(l[2],Math.hypot(l[0],l[1]))/P;return[v,D]}function N(e){const o=x.getBoundingClientRect();return[(e.clientX-o.left)*t.size[0]/o.width,(e.clientY-o.top)*t.size[1]/o.height]}const L=e=>e.map(o=>Math.round(o*1e6)/1e6);let k=null,z=!1;async function j(e,o){const a=await fetch(e,{method:"POST",headers:{"Content-Type":"application/json"},body:JSON.stringify(o)}),s=await a.json();if(!a.ok)throw new Error(s.error||`HTTP ${a.status}`);return s}function _(){k=JSON.parse(JSON.stringify(t.recipe)),z||J(),$()}async function J(){for(z=!0;k;){const e=k;k=null;try{const{stages:o}=await j("api/stages",e);q(o),o.codes&&m(`${e.steps.length} step(s), ${o.codes.length} stage(s)`)}catch(o){m(o.message,!0)}T()}z=!1,t.settled=!0,window.dispatchEvent(new Event("sw-drawn"))}function C(e){t.undo.push(JSON.stringify(t.recipe)),t.redo=[],t.recipe=e,_(),b()}function X(){t.undo.length&&(t.redo.push(JSON.stringify(t.recipe)),t.recipe=JSON.parse(t.undo.pop()),_(),b())}function G(){t.redo.length&&(t.undo.push(JSON.stringify(t.recipe)),t.recipe=JSON.parse(t.redo.pop()),_(),b())}function $(){const e=new URLSearchParams;e.set("view",t.view),e.set("size",`${t.size[0]}x${t.size[1]}`),t.ss!==2&&e.set("ss",t.ss),e.set("recipe",JSON.stringify(t.recipe)),history.replaceState(null,"",`?${e}`)}function W(){const e=new URLSearchParams(location.search);["flat","sphere","planet"].includes(e.get("view"))&&(t.view=e.get("view"));const o=/^(\d+)x(\d+)$/.exec(e.get("size")||"");o&&(t.size=[Math.min(+o[1],8192),Math.min(+o[2],8192)]);const a=+e.get("ss");if(a>=1&&a<=4&&(t.ss=Math.round(a)),e.get("recipe"))try{t.recipe=JSON.parse(e.get("recipe"))}catch(s){m(`recipe in the URL: ${s.message}`,!0)}}let p=null;x.addEventListener("mousedown",e=>{e.preventDefault();const[o,a]=N(e),s=I(o,a);if(e.altKey){t.pins=[t.pins[1],L(s)],F();return}if(t.view==="sphere"&&!e.shiftKey){p={look:!0,x:e.clientX,y:e.clientY,start:[...t.look]};return}p={from:L(s),base:JSON.parse(JSON.stringify(t.recipe)),moved:!1}});function Z(e){return{mobius:{from:[p.from,...t.pins],to:[L(e),...t.pins]}}}window.addEventListener("mousemove",e=>{if(!p)return;if(p.look){const a=t.look[2]/x.getBoundingClientRect().width;t.look[0]=p.start[0]+(e.clientX-p.x)*a,t.look[1]=Math.max(-89.9,Math.min(89.9,p.start[1]+(e.clientY-p.y)*a)),T();return}const o=I(...N(e));p.moved=!0,t.recipe={...p.base,steps:[...p.base.steps,Z(o)]},_()});window.addEventListener("mouseup",e=>{if(!p)return;const o=p;if(p=null,o.look||!o.moved)return;const a=I(...N(e));t.undo.push(JSON.stringify(o.base)),t.redo=[],t.recipe={...o.base,steps:[...o.base.steps,{mobius:{from:[o.from,...t.pins],to:[L(a),...t.pins]}}]},_(),b()});x.addEventListener("wheel",e=>{if(e.preventDefault(),e.ctrlKey||e.metaKey||e.altKey){const o=L(I(...N(e))),a=Math.exp(-e.deltaY*.002),s=[...t.recipe.steps],i=s[s.length-1];i&&i.zoom&&i.zoom.at[0]===o[0]&&i.zoom.at[1]===o[1]&&!p?s[s.length-1]={zoom:{at:o,factor:i.zoom.factor*a}}:s.push({zoom:{at:o,factor:a}}),C({...t.recipe,steps:s})}else t.view==="sphere"?(t.look[2]=Math.max(10,Math.min(170,t.look[2]*Math.exp(e.deltaY*.001))),T()):t.view==="planet"&&(t.planet=Math.max(.05,Math.min(20,t.planet*Math.exp(e.deltaY*.001))),T())},{passive:!1});window.addEventListener("keydown",e=>{if(e.ctrlKey||e.metaKey){if(e.key==="z"&&!e.shiftKey)X();else if(e.key==="y"||e.key==="z"&&e.shiftKey)G();else return;e.preventDefault()}});function F(){d("pins").textContent=t.pins.map(e=>`(${e[0].toFixed(1)}, ${e[1].toFixed(1)})`).join(" ")}function b(){const e=d("params");e.replaceChildren(),t.recipe.steps.forEach((o,a)=>{const[s,i]=Object.entries(o)[0],r=document.createElement("fieldset"),l=document.createElement("legend");l.textContent=`${a+1}. ${s}`;const v=document.createElement("button");v.textContent="×",v.title="remove this step",v.onclick=()=>C({...t.recipe,steps:t.recipe.steps.filter((f,E)=>E!==a)}),l.append(" ",v),r.append(l);const D=(f,E,h)=>{const c=E(),w=Math.max(1,Math.abs(c))*2,R=document.createElement("label"),u=document.createElement("input");u.type="range",u.min=c-w,u.max=c+w,u.step=w/500,u.value=c;const O=document.createElement("span");O.textContent=(+c).toPrecision(5);let A=null;u.oninput=()=>{A===null&&(A=JSON.stringify(t.recipe)),h(+u.value),O.textContent=(+u.value).toPrecision(5),_()},u.onchange=()=>{A!==null&&(t.undo.push(A),t.redo=[]),A=null,b()},R.append(`${f} `,u,O),r.append(R)},g=(f,E)=>{for(const[h,c]of Object.entries(f))typeof c=="number"?D(`${E}${h}`,()=>f[h],w=>f[h]=w):(Array.isArray(c)||c&&typeof c=="object"&&!c.keyframes)&&g(c,`${E}${h}.`)};g(i,""),e.append(r)})}function Q(e,o){const a=document.createElement("a");a.href=URL.createObjectURL(o),a.download=e,a.click()}function ee(){const e=JSON.stringify(t.recipe,null,1),[o,a]=t.size;return`cat > recipe.json <<'EOF'
${e}
EOF
spherewarp render recipe.json ${t.imageName} -o out.png --size ${o}x${a}`}function te(){d("undo").onclick=X,d("redo").onclick=G,d("save").onclick=()=>Q("recipe.json",new Blob([JSON.stringify(t.recipe,null,2)+`
`],{type:"application/json"})),d("load").onchange=async e=>{const o=e.target.files[0];if(o)try{const a=JSON.parse(await o.text());await j("api/stages",a),C(a)}catch(a){m(`${o.name}: ${a.message}`,!0)}},d("copy").onclick=async()=>{const e=ee();d("cli").value=e;try{await navigator.clipboard.writeText(e),m("copied the command")}catch{m("the command is in the box below (the clipboard is not available)")}},d("render").onclick=async()=>{try{const{job:e}=await j("api/render",t.recipe),o=async()=>{const a=await(await fetch(`api/render/${e}`)).json();if(a.error)return m(`render: ${a.error}`,!0);if(!a.done)return m(`rendering ${(100*a.progress).toFixed(0)}%`),setTimeout(o,300);m("rendered: downloading");const s=document.createElement("a");s.href=`api/render/${e}/file`,s.download="",s.click()};o()}catch(e){m(e.message,!0)}};for(const e of["flat","sphere","planet"])d(`v-${e}`).onclick=()=>{t.view=e,$(),T()};d("size").onchange=()=>{const e=/^(\d+)x(\d+)$/.exec(d("size").value);e&&(t.size=[+e[1],+e[2]],$(),T())}}async function ne(){const e=await(await fetch("api/state")).json();t.imageName=e.image.name,t.stageNames=Object.fromEntries(e.table.stages.map(s=>[s.code,s.name])),t.recipe=e.recipe;const o=e.image.width/e.image.height;t.size=[Math.min(e.image.width,2048),Math.round(Math.min(e.image.width,2048)/o)],W(),d("size").value=`${t.size[0]}x${t.size[1]}`,B(e.glsl_header);const a=new Image;a.src="image",await a.decode(),H(a),te(),F(),b(),_()}window.spherewarp={S:t,draw:T,pixelToLonLat:I,setRecipe:e=>C(e),setStages:e=>{q(e),T()},settle:()=>new Promise(e=>{if(!z&&!k)return e();window.addEventListener("sw-drawn",()=>e(),{once:!0})}),frameTime:e=>{const o=new Uint8Array(4),a=performance.now();for(let s=0;s<e;s++)T(),n.readPixels(0,0,1,1,n.RGBA,n.UNSIGNED_BYTE,o);return(performance.now()-a)/e}};ne().then(()=>window.spherewarp.ready=!0).catch(e=>{m(e.message,!0),window.spherewarp.error=e.message});
