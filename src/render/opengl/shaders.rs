//! The GLSL programs: `shade()` of the CPU renderers (`render::transport::lighting`)
//! written again for the fragment shader, a triangle program and an exact
//! sphere program (a bounding cube whose fragments intersect the sphere),
//! and their compilation into GL programs (`compile`).

use glow::HasContext;

/// The program linked from a vertex and a fragment shader's sources; the
/// shaders are let go once linked.
pub(super) unsafe fn compile(gl: &glow::Context, vertex: &str, fragment: &str) -> Result<glow::Program, String> {
    unsafe {
        let program = gl.create_program()?;
        let mut shaders = Vec::new();
        for (kind, source) in [(glow::VERTEX_SHADER, vertex), (glow::FRAGMENT_SHADER, fragment)] {
            let shader = gl.create_shader(kind)?;
            gl.shader_source(shader, source);
            gl.compile_shader(shader);
            if !gl.get_shader_compile_status(shader) {
                return Err(format!("a shader did not compile: {}", gl.get_shader_info_log(shader)));
            }
            gl.attach_shader(program, shader);
            shaders.push(shader);
        }
        gl.link_program(program);
        if !gl.get_program_link_status(program) {
            return Err(format!("a program did not link: {}", gl.get_program_info_log(program)));
        }
        for s in shaders {
            gl.detach_shader(program, s);
            gl.delete_shader(s);
        }
        Ok(program)
    }
}

/// What both fragment shaders share: the eye ray through this fragment's
/// sample position, computed as `CameraView::eye_ray` computes it, and the
/// shading of CGPP listing 15.19 (point lights `power / (4 pi d^2)`,
/// directional lights, Lambertian `k_L / pi` plus the material's glossy
/// lobe as `lighting::bsdf` evaluates it: normalized Blinn-Phong or Phong,
/// skipped where `s (1 - c) >= 20.7`, or GGX or Beckmann microfacets;
/// ambient `albedo * ambient`).
const COMMON: &str = r#"
uniform vec3 eye;
uniform mat3 camera_to_world;
uniform vec2 half_extent;
uniform vec2 image_size;
uniform vec2 sample_offset;
uniform float near_plane;
uniform float far_plane;
// Parallel eye rays down the view axis (CameraView::is_orthographic).
uniform bool orthographic;
uniform vec3 ambient;
uniform int light_count;
uniform bool y_down;

// Per material seven vec4: (k_L, glossy model), (k_G, sharpness), (k_M,
// roughness), (eta, Fresnel term), (k, diffuse model), (diffuse parameter,
// emission), (Ward's alpha u, alpha v, 0, 0); the glossy model 0 =
// Blinn-Phong, 1 = Phong, 2 = GGX, 3 = Beckmann, 4 = Ward.
layout(std430, binding = 0) readonly buffer Materials { vec4 materials[]; };
// Per light: (position or direction, 0 = point | 1 = directional), (power or irradiance, 0).
layout(std430, binding = 1) readonly buffer Lights { vec4 lights[]; };

const float PI = 3.14159265358979323846;

// Every texture's pyramid (`textures`): texels as linear RGB triples, and
// per level (first texel, width, height, 0), row 0 at the top. A texture
// is (its first level, its level count). They are read texel by texel and
// filtered here in float as `Texture::sample` filters: GL's own filtering
// would blend with its fixed-point weights and pick levels its own way.
layout(std430, binding = 4) readonly buffer Texels { float texel_data[]; };
layout(std430, binding = 5) readonly buffer Levels { ivec4 level_info[]; };

// The drawn material's texture and normal map (`Material::scaled`: uvs
// times uv_scale).
uniform bool has_albedo_map;
uniform ivec2 albedo_map;
uniform bool has_normal_map;
uniform ivec2 normal_map;
uniform vec2 uv_scale;
// TextureFilter: 0 nearest, 1 bilinear, 2 trilinear.
uniform int texture_filter;
uniform int anisotropic_taps;
// The material's Wrap: clamp to the edge texel, else repeat.
uniform bool wrap_clamp;
// Scene::miss_radiance: the latitude-longitude environment, else the background.
uniform bool has_environment;
uniform ivec2 environment;
uniform float environment_intensity;
uniform vec3 background;
// `--reflections env` with a depth to spare: mirrors look the environment up.
uniform bool mirror_env;

// asin and atan to float precision (Cephes' asinf and atanf): the
// driver's own are approximations (llvmpipe's asin is off by up to about
// 1e-4), enough to move a latitude across a texel's weight visibly.
float precise_asin(float x) {
    float a = abs(x);
    if (a > 1.0) return x > 0.0 ? PI / 2.0 : -PI / 2.0;
    float z;
    float s;
    bool wide = a > 0.5;
    if (wide) {
        z = 0.5 * (1.0 - a);
        s = sqrt(z);
    } else {
        z = a * a;
        s = a;
    }
    float r = ((((4.2163199048e-2 * z + 2.4181311049e-2) * z + 4.5470025998e-2) * z + 7.4953002686e-2) * z + 1.6666752422e-1) * z * s + s;
    if (wide) r = PI / 2.0 - 2.0 * r;
    return x < 0.0 ? -r : r;
}

float precise_atan(float x) {
    float a = abs(x);
    float y = 0.0;
    if (a > 2.414213562373095) {
        y = PI / 2.0;
        a = -1.0 / a;
    } else if (a > 0.4142135623730950) {
        y = PI / 4.0;
        a = (a - 1.0) / (a + 1.0);
    }
    float z = a * a;
    y += (((8.05374449538e-2 * z - 1.38776856032e-1) * z + 1.99777106478e-1) * z - 3.33329491539e-1) * z * a + a;
    return x < 0.0 ? -y : y;
}

// atan2(y, x) in (-pi, pi], as Rust's f32::atan2.
float precise_atan2(float y, float x) {
    if (x == 0.0) return y > 0.0 ? PI / 2.0 : (y < 0.0 ? -PI / 2.0 : 0.0);
    float t = precise_atan(y / x);
    if (x > 0.0) return t;
    return y < 0.0 ? t - PI : t + PI;
}

// MipLevel::texel_uv's addressing: i.rem_euclid(n) or i.clamp(0, n - 1).
int address(int i, int n, bool clamp_edge) {
    if (clamp_edge) return clamp(i, 0, n - 1);
    return i >= 0 ? i % n : (n - 1) - ((-(i + 1)) % n);
}

vec3 texel(ivec4 level, int x, int y, bool clamp_u, bool clamp_v) {
    int i = 3 * (level.x + address(y, level.z, clamp_v) * level.y + address(x, level.y, clamp_u));
    return vec3(texel_data[i], texel_data[i + 1], texel_data[i + 2]);
}

// glam's lerp: a (1 - s) + b s.
vec3 lerp3(vec3 a, vec3 b, float s) {
    return a * (1.0 - s) + b * s;
}

// MipLevel::position: texel-space x and y (row 0 at the top), or false
// when not finite or far outside.
bool level_position(vec2 uv, ivec4 level, out vec2 p) {
    p = vec2(uv.x * float(level.y), (1.0 - uv.y) * float(level.z));
    return !(any(isnan(p)) || any(isinf(p))) && abs(p.x) < 1e9 && abs(p.y) < 1e9;
}

// MipLevel::nearest on level 0.
vec3 nearest_at(ivec2 t, vec2 uv, bool clamp_edge) {
    ivec4 level = level_info[t.x];
    vec2 p;
    if (!level_position(uv, level, p)) return vec3(0.0);
    return texel(level, int(floor(p.x)), int(floor(p.y)), clamp_edge, clamp_edge);
}

// MipLevel::bilinear_uv on level `l`.
vec3 bilinear_at(ivec2 t, int l, vec2 uv, bool clamp_u, bool clamp_v) {
    ivec4 level = level_info[t.x + l];
    vec2 p;
    if (!level_position(uv, level, p)) return vec3(0.0);
    p -= 0.5;
    vec2 p0 = floor(p);
    vec2 f = p - p0;
    int x = int(p0.x), y = int(p0.y);
    vec3 top = lerp3(texel(level, x, y, clamp_u, clamp_v), texel(level, x + 1, y, clamp_u, clamp_v), f.x);
    vec3 bottom = lerp3(texel(level, x, y + 1, clamp_u, clamp_v), texel(level, x + 1, y + 1, clamp_u, clamp_v), f.x);
    return lerp3(top, bottom, f.y);
}

// Texture::level_of_detail: log2 of the longer pixel step in level-0
// texels, 0 when magnified, the coarsest level when unknown.
float level_of_step(ivec2 t, float rho) {
    float top = float(t.y - 1);
    if (isnan(rho)) return top;
    return rho <= 1.0 ? 0.0 : min(log2(rho), top);
}

float level_of_detail(ivec2 t, vec2 duv_dx, vec2 duv_dy) {
    vec2 size = vec2(level_info[t.x].yz);
    float along_x = length(duv_dx * size);
    float along_y = length(duv_dy * size);
    if (isnan(along_x) || isnan(along_y)) return float(t.y - 1);
    return level_of_step(t, max(along_x, along_y));
}

// Texture::trilinear: the two levels around lambda, blended.
vec3 trilinear_at(ivec2 t, vec2 s, float lambda) {
    float base = floor(lambda);
    int fine = int(base);
    float blend = lambda - base;
    vec3 a = bilinear_at(t, fine, s, wrap_clamp, wrap_clamp);
    if (blend == 0.0) return a;
    int coarse = min(fine + 1, t.y - 1);
    return lerp3(a, bilinear_at(t, coarse, s, wrap_clamp, wrap_clamp), blend);
}

// Texture::anisotropic: up to `anisotropic_taps` trilinear taps along the
// footprint's longer axis, each at the level of its share of that axis.
vec3 anisotropic_at(ivec2 t, vec2 s, vec2 dx, vec2 dy) {
    vec2 size = vec2(level_info[t.x].yz);
    float along_x = length(dx * size);
    float along_y = length(dy * size);
    if (isnan(along_x) || isnan(along_y) || isinf(along_x) || isinf(along_y)) return trilinear_at(t, s, level_of_detail(t, dx, dy));
    vec2 axis = along_x >= along_y ? dx : dy;
    float major = max(along_x, along_y);
    float minor = min(along_x, along_y);
    int taps = int(min(ceil(major / max(minor, 1e-12)), float(anisotropic_taps)));
    if (taps <= 1) return trilinear_at(t, s, level_of_detail(t, dx, dy));
    float lambda = level_of_step(t, max(major / float(taps), minor));
    vec3 sum = vec3(0.0);
    for (int k = 0; k < taps; k++) {
        float offset = (float(k) + 0.5) / float(taps) - 0.5;
        sum += trilinear_at(t, s + axis * offset, lambda);
    }
    return sum / float(taps);
}

// Texture::sample with the material's filter and wrap; `uv` and the
// footprint unscaled (uv_scale applied here, as Material::scaled does).
vec3 sample_texture(ivec2 t, vec2 uv, vec2 duv_dx, vec2 duv_dy) {
    vec2 s = uv * uv_scale;
    if (texture_filter == 0) return nearest_at(t, s, wrap_clamp);
    if (texture_filter == 1) return bilinear_at(t, 0, s, wrap_clamp, wrap_clamp);
    vec2 dx = duv_dx * uv_scale;
    vec2 dy = duv_dy * uv_scale;
    if (texture_filter == 4) return anisotropic_at(t, s, dx, dy);
    float lambda = level_of_detail(t, dx, dy);
    if (texture_filter == 3) {
        int level = lambda <= 0.5 ? 0 : min(int(ceil(lambda + 0.5)) - 1, t.y - 1);
        return bilinear_at(t, level, s, wrap_clamp, wrap_clamp);
    }
    return trilinear_at(t, s, lambda);
}

vec3 albedo_at(uint m, vec2 uv, vec2 duv_dx, vec2 duv_dy) {
    vec3 k = materials[7u * m].xyz;
    if (!has_albedo_map) return k;
    return k * sample_texture(albedo_map, uv, duv_dx, duv_dy);
}

vec3 normal_texel(vec2 uv, vec2 duv_dx, vec2 duv_dy) {
    return sample_texture(normal_map, uv, duv_dx, duv_dy);
}

// normal_map::mapped_normal: n bent by the texel in the frame of tangent t
// and handedness w; a straight-out texel or no frame leaves n as it is.
vec3 mapped_normal(vec3 n, vec3 t, float w, vec3 texel) {
    vec3 m = texel * 2.0 - 1.0;
    if (m.x == 0.0 && m.y == 0.0 && m.z > 0.0) return n;
    vec3 tp = t - n * dot(n, t);
    float lt = length(tp);
    if (!(lt > 0.0)) return n;
    vec3 tangent = tp / lt;
    vec3 bitangent = cross(n, tangent) * (w < 0.0 ? -1.0 : 1.0);
    vec3 r = tangent * m.x + bitangent * m.y + n * m.z;
    float l = length(r);
    return l > 0.0 && !isinf(l) ? r / l : n;
}

vec3 miss_radiance(vec3 dir) {
    if (!has_environment) return background;
    float u = 0.5 + (dir.x == 0.0 && dir.z == 0.0 ? 0.0 : precise_atan2(dir.x, -dir.z)) * (0.5 / PI);
    float v = 0.5 + precise_asin(clamp(dir.y, -1.0, 1.0)) / PI;
    // Environment::radiance: level 0, bilinear, repeating around, clamped at the poles.
    vec3 c = bilinear_at(environment, 0, vec2(u, v), false, true) * environment_intensity;
    return any(isnan(c)) || any(isinf(c)) ? vec3(0.0) : c;
}

#ifdef SHADOW_MAP
// `--shadows map`: the maps drawn by GL (`SHADOW_VERTEX` and friends), one
// layer per face; per face: (eye, half_x), (half_y, ortho, 0, 0) and the
// world-to-camera rows. A light's first face is `lights[2 i + 1].w`.
layout(std430, binding = 3) readonly buffer Faces { vec4 faces[]; };
uniform sampler2DArray shadow_maps;
uniform float map_size;
uniform float map_bias;
uniform bool slope_bias;
const float MAX_SLOPE = 10.0;

int cube_face(vec3 v) {
    vec3 a = abs(v);
    if (a.x >= a.y && a.x >= a.z) return v.x >= 0.0 ? 0 : 1;
    if (a.y >= a.z) return v.y >= 0.0 ? 2 : 3;
    return v.z >= 0.0 ? 4 : 5;
}

// ShadowMaps::occluder: the nearest texel's stored depth against the point's,
// with the slope-scaled bias in texels.
bool shadowed(int light, vec3 p, vec3 g, vec3 w_i) {
    vec4 la = lights[2 * light];
    int first = int(lights[2 * light + 1].w);
    if (first < 0) return false;
    bool point = la.w == 0.0;
    int face = point ? first + cube_face(p - la.xyz) : first;
    vec4 a = faces[5 * face];
    vec4 b = faces[5 * face + 1];
    mat3 w2c = transpose(mat3(faces[5 * face + 2].xyz, faces[5 * face + 3].xyz, faces[5 * face + 4].xyz));
    vec3 c = w2c * (p - a.xyz);
    float dist;
    float texel_w;
    vec2 img;
    if (point) {
        if (!(c.z < 0.0)) return false;
        float z = -c.z;
        dist = length(p - la.xyz);
        texel_w = 2.0 * z / map_size;
        float inv = 1.0 / -c.z;
        img = vec2((c.x * inv / a.w + 1.0) * 0.5 * map_size, (1.0 - c.y * inv / b.x) * 0.5 * map_size);
    } else {
        dist = -c.z;
        texel_w = 2.0 * max(a.w, b.x) / map_size;
        img = vec2((c.x / a.w + 1.0) * 0.5 * map_size, (1.0 - c.y / b.x) * 0.5 * map_size);
        if (!(img.x >= 0.0 && img.y >= 0.0 && img.x < map_size && img.y < map_size)) return false;
    }
    ivec2 texel = ivec2(clamp(floor(max(img, vec2(0.0))), vec2(0.0), vec2(map_size - 1.0)));
    float stored = texelFetch(shadow_maps, ivec3(texel.x, int(map_size) - 1 - texel.y, face), 0).r;
    float cos_n = clamp(abs(dot(g, w_i)), 1e-6, 1.0);
    float tan_n = slope_bias ? min(sqrt(max(1.0 - cos_n * cos_n, 0.0)) / cos_n, MAX_SLOPE) : 0.0;
    return dist - stored > map_bias * texel_w * (1.0 + tan_n);
}
#endif

#ifdef AREA_LIGHTS
// Per area light: (centre, first face of its cube map or -1), (radius,
// first point, point count, 0); per point of the pattern: (position, both
// sides emit), (unit normal, 0), (radiance over density and count, 0).
layout(std430, binding = 10) readonly buffer AreaLights { vec4 area_lights[]; };
layout(std430, binding = 11) readonly buffer AreaPoints { vec4 area_points[]; };
uniform int area_light_count;
#ifdef SHADOW_MAP
// --shadow-filter: 0 none, 1 pcf, 2 pcss; --pcf-radius in texels.
uniform int shadow_filter;
uniform float pcf_radius;
const int MAX_TAPS_PER_SIDE = 9;

// The taps around a point in one face of an area light's cube map, as
// `shadow::map::Taps` reads them: the texel `offset` texels from `centre`
// (clamped to the face), lit unless the point lies farther than its
// stored distance by more than the bias (which grows with the offset by
// the slope).
struct Taps { int face; vec2 centre; float dist; float texel_w; float tan_n; };

bool tap(Taps t, vec2 offset, out float stored) {
    float last = map_size - 1.0;
    int x = int(clamp(t.centre.x + offset.x, 0.0, last));
    int y = int(clamp(t.centre.y + offset.y, 0.0, last));
    stored = texelFetch(shadow_maps, ivec3(x, int(map_size) - 1 - y, t.face), 0).r;
    float tolerance = t.texel_w * (map_bias * (1.0 + t.tan_n) + length(offset) * t.tan_n);
    return !(t.dist - stored > tolerance);
}

// Taps::offsets: every texel within `radius` while that is at most
// MAX_TAPS_PER_SIDE per side, else a regular grid of that many.
int tap_half_count(float radius) {
    return min(int(ceil(max(radius, 0.0))), MAX_TAPS_PER_SIDE / 2);
}

float lit_fraction(Taps t, float radius) {
    int k = tap_half_count(radius);
    float step = k > 0 ? radius / float(k) : 0.0;
    int lit = 0;
    int total = 0;
    float stored;
    for (int j = -k; j <= k; j++) {
        for (int i = -k; i <= k; i++) {
            if (tap(t, vec2(float(i), float(j)) * step, stored)) lit++;
            total++;
        }
    }
    return float(lit) / float(total);
}

// The mean stored distance of the blockers within `radius`; -1 when none.
float mean_blocker_distance(Taps t, float radius) {
    int k = tap_half_count(radius);
    float step = k > 0 ? radius / float(k) : 0.0;
    float sum = 0.0;
    int count = 0;
    float stored;
    for (int j = -k; j <= k; j++) {
        for (int i = -k; i <= k; i++) {
            if (!tap(t, vec2(float(i), float(j)) * step, stored)) {
                sum += stored;
                count++;
            }
        }
    }
    return count > 0 ? sum / float(count) : -1.0;
}

// ShadowMaps::area_light_visibility: the fraction of area light `light`
// that the point sees, by its cube map read as --shadow-filter says.
float area_visibility(int light, vec3 p, vec3 g) {
    vec4 a = area_lights[2 * light];
    int first = int(a.w);
    if (first < 0) return 1.0;
    vec3 to_light = a.xyz - p;
    float to_length = length(to_light);
    vec3 w_i = to_length > 0.0 ? to_light / to_length : vec3(0.0);
    vec3 v = p - a.xyz;
    float dist = length(v);
    if (!(dist > 0.0)) return 1.0;
    int face = first + cube_face(v);
    vec4 fa = faces[5 * face];
    vec4 fb = faces[5 * face + 1];
    mat3 w2c = transpose(mat3(faces[5 * face + 2].xyz, faces[5 * face + 3].xyz, faces[5 * face + 4].xyz));
    vec3 c = w2c * (p - fa.xyz);
    if (!(c.z < 0.0)) return 1.0;
    float inv = 1.0 / -c.z;
    vec2 centre = vec2((c.x * inv / fa.w + 1.0) * 0.5 * map_size, (1.0 - c.y * inv / fb.x) * 0.5 * map_size);
    float cos_n = clamp(abs(dot(g, w_i)), 1e-6, 1.0);
    float tan_n = slope_bias ? min(sqrt(max(1.0 - cos_n * cos_n, 0.0)) / cos_n, MAX_SLOPE) : 0.0;
    Taps t = Taps(face, centre, dist, 2.0 * -c.z / map_size, tan_n);
    if (shadow_filter == 0) return lit_fraction(t, 0.0);
    if (shadow_filter == 1) return lit_fraction(t, pcf_radius);
    // PCSS: the light as a disc of equal area, the blocker search in the
    // cone from the point to the light from a quarter of the way, then the
    // penumbra's width by similar triangles.
    float radius = area_lights[2 * light + 1].x * sqrt(2.0 / PI);
    float near_d = 0.25 * dist;
    float search = min(radius * (dist - near_d) / (dist * near_d), 0.6) * map_size * 0.5;
    float blocker = mean_blocker_distance(t, search);
    if (blocker < 0.0) return 1.0;
    float penumbra = radius * (dist - blocker) / (blocker * dist) * map_size * 0.5;
    return lit_fraction(t, min(penumbra, map_size * 0.25));
}
#endif
#endif

#ifdef VIEWS
// The surface each fragment saw, for the debug views and pixel readback
// (`views`): position and 1, shading normal and back-face flag, geometric
// normal, barycentric weights, uv, and (kind + 1, primitive) (0: nothing).
layout(location = 1) out vec4 out_position;
layout(location = 2) out vec4 out_normal;
layout(location = 3) out vec4 out_face_normal;
layout(location = 4) out vec4 out_barycentric;
layout(location = 5) out vec4 out_uv;
layout(location = 6) out uvec4 out_id;
void write_surface(vec3 p, vec3 n, bool back, vec3 g, vec3 b, vec2 uv, uint kind, uint primitive) {
    out_position = vec4(p, 1.0);
    out_normal = vec4(n, back ? 1.0 : 0.0);
    out_face_normal = vec4(g, 0.0);
    out_barycentric = vec4(b, 0.0);
    out_uv = vec4(uv, 0.0, 0.0);
    out_id = uvec4(kind + 1u, primitive, 0u, 0u);
}
#endif

// With --msaa, a program shaded per sample (the spheres, whose coverage is
// their ray test's) looks through its own sample; others through the pixel's.
vec2 sample_shift() {
#if defined(MSAA) && defined(PER_SAMPLE)
    return vec2(gl_SamplePosition.x - 0.5, y_down ? gl_SamplePosition.y - 0.5 : 0.5 - gl_SamplePosition.y);
#else
    return vec2(0.0);
#endif
}

// Camera-space point (z = -1) of the image plane at this fragment's sample,
// pixel rows top-down.
vec3 image_point() {
    vec2 shift = sample_shift();
    float px = floor(gl_FragCoord.x) + sample_offset.x + shift.x;
    float row = y_down ? floor(gl_FragCoord.y) : image_size.y - 1.0 - floor(gl_FragCoord.y);
    float py = row + sample_offset.y + shift.y;
    return vec3((2.0 * px / image_size.x - 1.0) * half_extent.x, (1.0 - 2.0 * py / image_size.y) * half_extent.y, -1.0);
}

// Camera-space direction of this fragment's eye ray: through the image
// point (z = -1), or down the view axis along parallel rays.
vec3 camera_dir() {
    return orthographic ? vec3(0.0, 0.0, -1.0) : image_point();
}

// Camera-space start of this fragment's eye ray on the near plane, as
// CameraView::eye_ray places it (beside the axis along parallel rays).
vec3 ray_start() {
    return orthographic ? vec3(image_point().xy, -near_plane) : camera_dir() * near_plane;
}

// How far the eye ray's start moves per pixel step `step` (camera space,
// in the image plane) at view depth `w`: the step itself along parallel
// rays, the step scaled by depth through one centre.
vec3 ray_step(vec3 step, float w) {
    return orthographic ? step : step * w;
}

// The reversed depth (near 1, far 0) GL stores for view depth `w`: 1/w
// rescaled through one centre, linear in w along parallel rays.
float stored_depth(float w) {
    if (orthographic) return clamp((far_plane - w) / (far_plane - near_plane), 0.0, 1.0);
    return clamp(near_plane * (far_plane - w) / ((far_plane - near_plane) * w), 0.0, 1.0);
}

vec3 normalize_or_zero(vec3 v) {
    float l = length(v);
    return l > 0.0 ? v / l : vec3(0.0);
}

// tan^2 of the angle whose cosine is c.
float tan2_of(float c) {
    float c2 = c * c;
    return max(1.0 - c2, 0.0) / c2;
}

// The microfacet distribution D (GGX or Beckmann) at alpha a, as
// `microfacet::ggx_d` and `beckmann_d` compute it.
float microfacet_d(float cos_h, float a, bool ggx) {
    if (cos_h <= 0.0) return 0.0;
    float c2 = cos_h * cos_h;
    float a2 = a * a;
    float d;
    if (ggx) {
        float e = max(1.0 - c2, 0.0) / a2 + c2;
        d = 1.0 / (PI * a2 * e * e);
    } else {
        d = exp(-tan2_of(cos_h) / a2) / (PI * a2 * (c2 * c2));
    }
    return d * cos_h > 1e-20 ? d : 0.0;
}

// Smith's one-sided shadowing G1 of a direction v (`cos_v = n.v`,
// `v_h = v.h`), as `microfacet::ggx_g1` and `beckmann_g1` compute it.
float smith_g1(float cos_v, float v_h, float a, bool ggx) {
    if (v_h * cos_v <= 0.0) return 0.0;
    float t = a * a * tan2_of(cos_v);
    if (ggx) return 2.0 / (1.0 + sqrt(1.0 + t));
    if (t <= 0.0) return 1.0;
    float b = 1.0 / sqrt(t);
    if (b >= 1.6) return 1.0;
    return (3.535 * b + 2.181 * b * b) / (1.0 + 2.276 * b + 2.577 * b * b);
}

// The diffuse lobe's factor on k_L, as `lighting::diffuse` computes it:
// model 0 = Lambert, 1 = Oren-Nayar (sigma), 2 = Minnaert (darkening),
// 3 = toon (bands).
float diffuse_factor(float model, float param, vec3 n, vec3 w_i, vec3 w_o) {
    float inv_pi = 1.0 / PI;
    if (model == 0.0) return inv_pi;
    float cos_i = dot(n, w_i);
    float cos_o = dot(n, w_o);
    if (model == 1.0) {
        float s2 = param * param;
        float a = 1.0 - 0.5 * s2 / (s2 + 0.33);
        float b = 0.45 * s2 / (s2 + 0.09);
        float t = max(dot(w_i - n * cos_i, w_o - n * cos_o), 0.0) / max(max(cos_i, cos_o), 1e-4);
        return inv_pi * (a + b * t);
    }
    if (model == 2.0) {
        float ratio = max(cos_i, 1e-4) / max(cos_o, 1e-4);
        return inv_pi * ((param + 1.0) * 0.5 * pow(ratio, param - 1.0));
    }
    float q = min(floor(max(cos_i, 0.0) * param + 0.5) / param, 1.0);
    return q > 0.0 ? inv_pi * (q / cos_i) : 0.0;
}

// A conductor's Fresnel reflectance, as `lighting::conductor_fresnel`.
float conductor_fresnel(float c, float eta, float k) {
    float cos2 = c * c;
    float sin2 = 1.0 - cos2;
    float t = eta * eta - k * k - sin2;
    float a2b2 = sqrt(max(t * t + 4.0 * eta * eta * k * k, 0.0));
    float a = sqrt(max((a2b2 + t) * 0.5, 0.0));
    float two_ac = 2.0 * a * c;
    float r_s = (a2b2 + cos2 - two_ac) / (a2b2 + cos2 + two_ac);
    float p1 = a2b2 * cos2 + sin2 * sin2;
    float p2 = two_ac * sin2;
    float r_p = r_s * (p1 - p2) / (p1 + p2);
    float f = (r_s + r_p) * 0.5;
    return isnan(f) ? 1.0 : f;
}

// The glossy lobe's weight, as `lighting::glossy_weight`: k_G (Fresnel
// term 0), Schlick with F0 = k_G (1), or k_G times a conductor's
// reflectance (2), at the cosine c between the light and the half vector.
vec3 glossy_weight(vec3 glossy, vec4 eta, vec3 k, float c) {
    if (eta.w == 0.0) return glossy;
    c = clamp(c, 0.0, 1.0);
    if (eta.w == 1.0) {
        float m = 1.0 - c;
        return glossy + (vec3(1.0) - glossy) * (m * m * m * m * m);
    }
    return glossy * vec3(conductor_fresnel(c, eta.x, k.x), conductor_fresnel(c, eta.y, k.y), conductor_fresnel(c, eta.z, k.z));
}

// lighting::ward_frame: the unit tangent t made orthogonal to n, or where
// that leaves nothing a fixed perpendicular (x cross n, or y cross n when n
// is near x); the bitangent is n cross t.
void ward_frame(vec3 n, vec3 tangent, out vec3 t, out vec3 b) {
    t = normalize_or_zero(tangent - n * dot(n, tangent));
    if (t == vec3(0.0)) t = normalize(cross(abs(n.x) > 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0), n));
    b = cross(n, t);
}

// lighting::bsdf: material m's BSDF for light from w_i seen from w_o, at a
// surface of shading normal n and tangent `tangent` (read by Ward's lobe
// only; cos_theta = n . w_i > 0).
vec3 bsdf(vec3 n, vec3 tangent, vec3 w_i, vec3 w_o, float cos_theta, uint m, vec3 albedo) {
    vec3 glossy = materials[7u * m + 1u].xyz;
    float s = materials[7u * m + 1u].w;
    float model = materials[7u * m].w;
    float alpha = materials[7u * m + 2u].w;
    vec4 fresnel = materials[7u * m + 3u];
    vec4 conductor_k = materials[7u * m + 4u];
    float diffuse_param = materials[7u * m + 5u].x;
    vec3 f = albedo * diffuse_factor(conductor_k.w, diffuse_param, n, w_i, w_o);
    if (glossy != vec3(0.0)) {
        vec3 w_h = normalize_or_zero(w_i + w_o);
        vec3 weight = glossy_weight(glossy, fresnel, conductor_k.xyz, dot(w_i, w_h));
        if (model == 0.0) {
            float c = max(dot(n, w_h), 0.0);
            if (s * (1.0 - c) < 20.7) {
                f += weight * ((s + 2.0) * (s + 4.0) / (8.0 * PI * (exp2(max(-0.5 * s, -126.0)) + s)) * pow(c, s));
            }
        } else if (model == 1.0) {
            vec3 r = (2.0 * dot(n, w_o)) * n - w_o;
            float c = max(dot(r, w_i), 0.0);
            if (s * (1.0 - c) < 20.7) {
                f += weight * ((s + 2.0) * (0.5 / PI) * pow(c, s));
            }
        } else if (model == 4.0) {
            // lighting::ward_lobe: exp(-((h.t / a_u)^2 + (h.b / a_v)^2) / (h.n)^2)
            // over 4 pi a_u a_v sqrt(cos_i cos_o), with h = w_i + w_o unnormalized.
            float cos_o = dot(n, w_o);
            if (cos_o > 0.0) {
                vec2 a = materials[7u * m + 6u].xy;
                vec3 t;
                vec3 b;
                ward_frame(n, tangent, t, b);
                vec3 h = w_i + w_o;
                float x = dot(h, t) / a.x;
                float y = dot(h, b) / a.y;
                float z = dot(h, n);
                float e = -((x * x + y * y) / (z * z)) * 1.44269504088896340736;
                if (e >= -126.0) {
                    f += weight * (exp2(e) / (4.0 * PI * a.x * a.y * sqrt(max(cos_theta * cos_o, 0.0))));
                }
            }
        } else {
            float cos_o = dot(n, w_o);
            if (cos_o > 0.0) {
                bool ggx = model == 2.0;
                float d = microfacet_d(dot(n, w_h), alpha, ggx);
                float g2 = smith_g1(cos_theta, dot(w_i, w_h), alpha, ggx) * smith_g1(cos_o, dot(w_o, w_h), alpha, ggx);
                f += weight * (d * g2 / (4.0 * cos_theta * cos_o));
            }
        }
    }
    return f;
}

// The emission of material m seen from the front (emitters::emitted).
vec3 emitted(uint m, bool back) {
    return back ? vec3(0.0) : materials[7u * m + 5u].yzw;
}

#ifdef AREA_LIGHTS
// Direct light from the area lights: the fixed pattern of points over the
// emitters (`scene_data::area_lights`), each weighted as a light sample of
// `sampled_light::sampled_direct` is without MIS (radiance, BSDF and both
// cosines over the squared distance and the point's density), and each
// light's sum multiplied by the visibility its shadow map gives.
vec3 area_direct(vec3 p, vec3 n, vec3 t, vec3 g, vec3 w_o, uint m, vec3 albedo) {
    vec3 l_o = vec3(0.0);
    for (int i = 0; i < area_light_count; i++) {
        vec4 b = area_lights[2 * i + 1];
        int first = int(b.y);
        int count = int(b.z);
        vec3 sum = vec3(0.0);
        for (int k = first; k < first + count; k++) {
            vec4 q = area_points[3 * k];
            vec3 normal = area_points[3 * k + 1].xyz;
            vec3 value = area_points[3 * k + 2].xyz;
            vec3 offset = q.xyz - p;
            float d2 = dot(offset, offset);
            float d = sqrt(d2);
            if (!(d > 0.0)) continue;
            vec3 w_i = offset / d;
            float cos_l = -dot(normal, w_i);
            if (q.w != 0.0) cos_l = abs(cos_l);
            if (!(cos_l > 1e-7)) continue;
            float cos_theta = dot(n, w_i);
            if (cos_theta <= 0.0 || dot(w_i, g) <= 0.0) continue;
            sum += value * bsdf(n, t, w_i, w_o, cos_theta, m, albedo) * (cos_theta * cos_l / d2);
        }
#ifdef SHADOW_MAP
        if (sum != vec3(0.0)) sum *= area_visibility(i, p, g);
#endif
        l_o += sum;
    }
    return l_o;
}
#endif

#ifdef ENVIRONMENT_LIGHT
// The [environment] as a light: directions importance-sampled from its map
// (`scene_data::environment_light`) after their count, (unit direction, 0)
// and (radiance over density and count, 0) each, weighted as light samples
// without MIS are. Unshadowed: GL casts no rays, and no map holds the
// sky's shadows.
layout(std430, binding = 12) readonly buffer EnvironmentSamples { vec4 environment_samples[]; };

vec3 environment_direct(vec3 n, vec3 t, vec3 g, vec3 w_o, uint m, vec3 albedo) {
    vec3 l_o = vec3(0.0);
    int count = int(environment_samples[0].x);
    for (int k = 0; k < count; k++) {
        vec3 w_i = environment_samples[1 + 2 * k].xyz;
        float cos_theta = dot(n, w_i);
        if (cos_theta <= 0.0 || dot(w_i, g) <= 0.0) continue;
        l_o += environment_samples[2 + 2 * k].xyz * bsdf(n, t, w_i, w_o, cos_theta, m, albedo) * cos_theta;
    }
    return l_o;
}
#endif

vec3 shade(vec3 p, vec3 n, vec3 t, vec3 g, vec3 w_o, uint m, vec3 albedo) {
    vec3 l_o = albedo * ambient;
    for (int i = 0; i < light_count; i++) {
        vec4 a = lights[2 * i];
        vec3 b = lights[2 * i + 1].xyz;
        vec3 w_i;
        vec3 incident;
        if (a.w == 0.0) {
            vec3 offset = a.xyz - p;
            float d = length(offset);
            if (!(d > 0.0)) continue;
            w_i = offset / d;
            incident = b / ((4.0 * PI) * d * d);
        } else {
            w_i = -a.xyz;
            incident = b;
        }
        float cos_theta = dot(w_i, n);
        if (cos_theta <= 0.0 || incident == vec3(0.0)) continue;
#ifdef SHADOW_MAP
        if (shadowed(i, p, g, w_i)) continue;
#endif
        l_o += (incident * bsdf(n, t, w_i, w_o, cos_theta, m, albedo)) * cos_theta;
    }
#ifdef AREA_LIGHTS
    l_o += area_direct(p, n, t, g, w_o, m, albedo);
#endif
#ifdef ENVIRONMENT_LIGHT
    l_o += environment_direct(n, t, g, w_o, m, albedo);
#endif
    vec3 mirror = materials[7u * m + 2u].xyz;
    if (mirror_env && mirror != vec3(0.0)) {
        float cos_o = clamp(dot(w_o, g), -1.0, 1.0);
        l_o += mirror * miss_radiance(normalize(2.0 * cos_o * g - w_o));
    }
    return l_o;
}
"#;

/// The triangles' vertex shader; with `INSTANCED` defined, the two-level
/// layer's copies: each vertex of the shared mesh placed by the copy's
/// matrix in the very order of operations `Placement::apply` uses
/// (`precise`: no fused multiply-adds), so a copy's triangles land where
/// flattening would put them.
pub fn triangle_vertex(defines: &str) -> String {
    format!(
        "#version 450 core\n{defines}{}",
        r#"
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec3 face_normal;
layout(location = 3) in uint material;
layout(location = 4) in vec2 uv;
layout(location = 5) in vec4 tangent;
#ifdef INSTANCED
// Per copy: the placement's matrix columns, its normal matrix columns,
// (first virtual triangle less the mesh's first, material or ~0, mirrors).
layout(location = 6) in vec3 m0;
layout(location = 7) in vec3 m1;
layout(location = 8) in vec3 m2;
layout(location = 9) in vec3 m3;
layout(location = 10) in vec3 n0;
layout(location = 11) in vec3 n1;
layout(location = 12) in vec3 n2;
layout(location = 13) in uvec3 copy;
#endif
uniform vec3 eye;
uniform mat3 world_to_camera;
uniform vec2 half_extent;
// Moves the image so that GL's pixel centre samples this pass's sample position (NDC units).
uniform vec2 ndc_shift;
// The image drawn upside down, GL's row 0 the top row (see `pass::render`).
uniform bool y_down;
uniform float near_plane;
uniform float far_plane;
uniform bool orthographic;
out vec3 v_position;
out vec3 v_normal;
flat out vec3 v_face_normal;
flat out uint v_material;
out vec2 v_uv;
out vec3 v_tangent;
flat out float v_handedness;
out vec3 v_corner;
flat out uint v_primitive;

// glam's normalize_or_zero.
vec3 normalize_or_zero_v(vec3 v) {
    float r = 1.0 / length(v);
    return !isinf(r) && !isnan(r) && r > 0.0 ? v * r : vec3(0.0);
}

void main() {
    int k = gl_VertexID % 3;
#ifdef INSTANCED
    // Mat4::transform_point3: ((x_axis x + y_axis y) + z_axis z) + w_axis.
    precise vec3 p = m0 * position.x;
    p = m1 * position.y + p;
    p = m2 * position.z + p;
    p = m3 + p;
    precise vec3 nn = n0 * normal.x;
    nn = n1 * normal.y + nn;
    nn = n2 * normal.z + nn;
    vec3 world_normal = normalize_or_zero_v(nn);
    // The face normal of the placed corners is the normal matrix's image
    // of the mesh's (mirrored corners are swapped back, so it keeps its side).
    vec3 world_face = normalize(mat3(n0, n1, n2) * face_normal);
    uint world_material = copy.y == 0xffffffffu ? material : copy.y;
    // A mirroring placement swaps corners 1 and 2.
    if (copy.z != 0u && k != 0) k = 3 - k;
    uint primitive = copy.x + uint(gl_VertexID / 3);
#else
    vec3 p = position;
    vec3 world_normal = normal;
    vec3 world_face = face_normal;
    uint world_material = material;
    uint primitive = uint(gl_VertexID / 3);
#endif
    vec3 c = world_to_camera * (p - eye);
    // Reversed depth with glClipControl(ZERO_TO_ONE): near -> 1, far -> 0;
    // parallel rays divide by nothing (w = 1), and their depth is linear.
    float w = orthographic ? 1.0 : -c.z;
    float z = orthographic ? (far_plane + c.z) / (far_plane - near_plane) : near_plane * (far_plane - w) / (far_plane - near_plane);
    gl_Position = vec4(c.x / half_extent.x + ndc_shift.x * w, (c.y / half_extent.y + ndc_shift.y * w) * (y_down ? -1.0 : 1.0), z, w);
    v_position = p;
    v_normal = world_normal;
    v_face_normal = world_face;
    v_material = world_material;
    v_uv = uv;
    v_tangent = tangent.xyz;
    v_handedness = tangent.w;
    // One-hot per corner: interpolated, the barycentric weights.
    v_corner = vec3(k == 0, k == 1, k == 2);
    v_primitive = primitive;
}
"#
    )
}

pub fn triangle_fragment(defines: &str) -> String {
    format!(
        "#version 450 core\n{defines}{COMMON}{}",
        r#"
uniform bool flat_shading;
// With --msaa, a fragment is shaded once, at a sample the triangle covers
// (the CPU's MSAA shades at the covered sample nearest the centre).
#ifdef MSAA
#define SAMPLED centroid
#else
#define SAMPLED
#endif
SAMPLED in vec3 v_position;
SAMPLED in vec3 v_normal;
flat in vec3 v_face_normal;
flat in uint v_material;
SAMPLED in vec2 v_uv;
SAMPLED in vec3 v_tangent;
flat in float v_handedness;
SAMPLED in vec3 v_corner;
flat in uint v_primitive;
layout(location = 0) out vec4 colour;
void main() {
    vec3 big_d = camera_to_world * camera_dir();
    vec3 dir = normalize(big_d);
    vec3 g = v_face_normal;
    // The footprint the CPU renderers use: the camera ray's differentials
    // carried to the triangle's plane (Igehy). The uv is affine in the
    // position across the plane, so the quad's differences of both give
    // the map from one to the other; GL's own differences alone would be
    // one-sided and one per quad.
    vec3 ex = dFdx(v_position);
    vec3 ey = dFdy(v_position);
    vec2 ux = dFdx(v_uv);
    vec2 uy = dFdy(v_uv);
    vec2 duv_dx = ux;
    vec2 duv_dy = uy;
    {
        float t = dot(v_position - eye, -camera_to_world[2]);
        float xx = dot(ex, ex), xy = dot(ex, ey), yy = dot(ey, ey);
        float det = xx * yy - xy * xy;
        float facing = dot(big_d, g);
        if (det > 0.0 && facing != 0.0) {
            vec3 steps[2] = vec3[2](camera_to_world * vec3(2.0 * half_extent.x / image_size.x, 0.0, 0.0), camera_to_world * vec3(0.0, -2.0 * half_extent.y / image_size.y, 0.0));
            vec2 d[2];
            for (int k = 0; k < 2; k++) {
                vec3 dd = ray_step(steps[k], t);
                vec3 dp = dd - big_d * (dot(dd, g) / facing);
                float a = (yy * dot(ex, dp) - xy * dot(ey, dp)) / det;
                float b = (xx * dot(ey, dp) - xy * dot(ex, dp)) / det;
                d[k] = a * ux + b * uy;
            }
            if (!(any(isnan(d[0])) || any(isinf(d[0])) || any(isnan(d[1])) || any(isinf(d[1])))) {
                duv_dx = d[0];
                duv_dy = d[1];
            }
        }
    }
    float l = length(v_normal);
    vec3 n = l > 0.0 ? v_normal / l : g;
    // The map bends the front side's normal (normal_map::apply).
    if (has_normal_map) n = mapped_normal(n, v_tangent, v_handedness, normal_texel(v_uv, duv_dx, duv_dy));
    bool back = dot(g, dir) > 0.0;
    if (back) {
        g = -g;
        n = -n;
    }
#ifdef VIEWS
    write_surface(v_position, n, back, g, v_corner, v_uv, 0u, v_primitive);
#endif
    if (flat_shading) n = g;
    vec3 albedo = albedo_at(v_material, v_uv, duv_dx, duv_dy);
    colour = vec4(shade(v_position, n, v_tangent, g, -dir, v_material, albedo) + emitted(v_material, back), 1.0);
}
"#
    )
}

pub const SPHERE_VERTEX: &str = r#"#version 450 core
layout(location = 0) in vec3 corner;
struct Sphere { vec4 centre_radius; uvec4 material; };
layout(std430, binding = 2) readonly buffer Spheres { Sphere spheres[]; };
uniform vec3 eye;
uniform mat3 world_to_camera;
uniform vec2 half_extent;
uniform vec2 ndc_shift;
// The image drawn upside down, GL's row 0 the top row (see `pass::render`).
uniform bool y_down;
uniform float near_plane;
uniform float far_plane;
uniform bool orthographic;
// Spheres are drawn one material at a time: the first one of this draw.
uniform int first_sphere;
flat out int v_sphere;
void main() {
    int index = first_sphere + gl_InstanceID;
    vec4 s = spheres[index].centre_radius;
    // Slightly larger than the sphere, so its silhouette is always inside.
    vec3 position = s.xyz + corner * (s.w * 1.01);
    vec3 c = world_to_camera * (position - eye);
    float w = orthographic ? 1.0 : -c.z;
    float z = orthographic ? (far_plane + c.z) / (far_plane - near_plane) : near_plane * (far_plane - w) / (far_plane - near_plane);
    gl_Position = vec4(c.x / half_extent.x + ndc_shift.x * w, (c.y / half_extent.y + ndc_shift.y * w) * (y_down ? -1.0 : 1.0), z, w);
    v_sphere = index;
}
"#;

pub fn sphere_fragment(defines: &str) -> String {
    format!(
        "#version 450 core\n{defines}#define PER_SAMPLE 1\n{COMMON}{}",
        r#"
struct Sphere { vec4 centre_radius; uvec4 material; };
layout(std430, binding = 2) readonly buffer Spheres { Sphere spheres[]; };
flat in int v_sphere;
layout(location = 0) out vec4 colour;
void main() {
    vec4 s = spheres[v_sphere].centre_radius;
    uint m = spheres[v_sphere].material.x;
    vec3 d = camera_dir();
    vec3 dir = normalize(camera_to_world * d);
    vec3 origin = eye + camera_to_world * ray_start();
    // The ray tracer's test (intersect_sphere): from outside only, 0 < t < far.
    vec3 f = origin - s.xyz;
    float b = -dot(f, dir);
    vec3 to_line = f + dir * b;
    float dist = length(to_line);
    float disc = (s.w - dist) * (s.w + dist);
    if (disc < 0.0 || !(length(f) > s.w)) discard;
    float t = b - sqrt(disc);
    if (t <= 0.0 || t >= (far_plane - near_plane) * length(d)) discard;
    vec3 p = origin + dir * t;
    vec3 o = (p - s.xyz) / s.w;
    float w = dot(p - eye, -camera_to_world[2]);
    // Scene::sphere_hit's uv: u around +y, v from the south pole up.
    vec2 uv = vec2(0.5 + (o.x == 0.0 && o.z == 0.0 ? 0.0 : precise_atan2(o.z, o.x)) * (-0.5 / PI), 0.5 + precise_asin(clamp(o.y, -1.0, 1.0)) / PI);
    // Its footprint from the camera ray's differentials carried to the
    // tangent plane (Igehy), as the ray casters do: the 2x2 quad's
    // differences would straddle the silhouette and the u seam.
    vec3 big_d = camera_to_world * d;
    vec3 steps[2] = vec3[2](camera_to_world * vec3(2.0 * half_extent.x / image_size.x, 0.0, 0.0), camera_to_world * vec3(0.0, -2.0 * half_extent.y / image_size.y, 0.0));
    vec2 duv[2];
    for (int k = 0; k < 2; k++) {
        vec3 dd = ray_step(steps[k], w);
        vec3 dp = dd - big_d * (dot(dd, o) / dot(big_d, o));
        vec3 q = dp / s.w;
        float ring = max(o.x * o.x + o.z * o.z, 1e-12);
        duv[k] = vec2(-(o.x * q.z - o.z * q.x) / (2.0 * PI * ring), q.y / (PI * sqrt(max(1.0 - o.y * o.y, 1e-12))));
        if (any(isnan(duv[k])) || any(isinf(duv[k]))) duv[k] = vec2(1.0);
    }
    vec3 n = o;
    if (has_normal_map) n = mapped_normal(n, vec3(o.z, 0.0, -o.x), 1.0, normal_texel(uv, duv[0], duv[1]));
    vec3 g = o;
    bool back = dot(g, dir) > 0.0;
    if (back) {
        g = -g;
        n = -n;
    }
#ifdef VIEWS
    write_surface(p, n, back, g, vec3(0.0), uv, 1u, uint(v_sphere));
#endif
    gl_FragDepth = stored_depth(w);
    colour = vec4(shade(p, n, vec3(o.z, 0.0, -o.x), g, -dir, m, albedo_at(m, uv, duv[0], duv[1])) + emitted(m, back), 1.0);
}
"#
    )
}

/// The environment behind everything: one triangle over the whole image,
/// each fragment showing what its eye ray sees when it hits nothing.
pub const BACKGROUND_VERTEX: &str = r#"#version 450 core
void main() {
    vec2 corner = vec2(float((gl_VertexID & 1) * 4 - 1), float((gl_VertexID & 2) * 2 - 1));
    gl_Position = vec4(corner, 0.0, 1.0);
}
"#;

pub fn background_fragment() -> String {
    format!(
        "#version 450 core\n{COMMON}{}",
        r#"
layout(location = 0) out vec4 colour;
void main() {
    colour = vec4(miss_radiance(normalize(camera_to_world * camera_dir())), 1.0);
}
"#
    )
}

/// The shadow pass: each face of each light's map drawn from the light
/// (`shadow_map::light_views`), storing what `shadow_map` stores: the
/// distance from the light (perspective faces) or the depth along the
/// light's direction (orthographic), nearest first.
pub const SHADOW_VERTEX: &str = r#"#version 450 core
layout(location = 0) in vec3 position;
uniform vec3 eye;
uniform mat3 world_to_camera;
uniform vec2 half_extent;
uniform bool ortho;
uniform float near_plane;
// Orthographic: the range of depths of the scene's box, mapped to [1, 0].
uniform vec2 depth_range;
out vec3 v_position;
out float v_depth;
void main() {
    vec3 c = world_to_camera * (position - eye);
    float d = -c.z;
    if (ortho) {
        gl_Position = vec4(c.x / half_extent.x, c.y / half_extent.y, (depth_range.y - d) / (depth_range.y - depth_range.x), 1.0);
    } else {
        gl_Position = vec4(c.x / half_extent.x, c.y / half_extent.y, near_plane, d);
    }
    v_position = position;
    v_depth = d;
}
"#;

pub const SHADOW_FRAGMENT: &str = r#"#version 450 core
uniform vec3 eye;
uniform bool ortho;
in vec3 v_position;
in float v_depth;
layout(location = 0) out float stored;
void main() {
    stored = ortho ? v_depth : length(v_position - eye);
}
"#;

/// Spheres in the shadow pass: the bounding cube again, each texel's ray
/// from the light meeting the sphere exactly (`shadow_map`'s sphere_entry).
pub const SHADOW_SPHERE_VERTEX: &str = r#"#version 450 core
layout(location = 0) in vec3 corner;
struct Sphere { vec4 centre_radius; uvec4 material; };
layout(std430, binding = 2) readonly buffer Spheres { Sphere spheres[]; };
uniform vec3 eye;
uniform mat3 world_to_camera;
uniform vec2 half_extent;
uniform bool ortho;
uniform float near_plane;
uniform vec2 depth_range;
// An area light's own object (-1: none), left out of its map.
uniform int skip_object;
flat out int v_sphere;
void main() {
    vec4 s = spheres[gl_InstanceID].centre_radius;
    vec3 c = world_to_camera * (s.xyz + corner * (s.w * 1.01) - eye);
    float d = -c.z;
    if (ortho) {
        gl_Position = vec4(c.x / half_extent.x, c.y / half_extent.y, (depth_range.y - d) / (depth_range.y - depth_range.x), 1.0);
    } else {
        gl_Position = vec4(c.x / half_extent.x, c.y / half_extent.y, near_plane, d);
    }
    // Every corner outside the clip volume on the same side: nothing is drawn.
    if (int(spheres[gl_InstanceID].material.y) == skip_object) gl_Position = vec4(2.0, 2.0, 0.5, 1.0);
    v_sphere = gl_InstanceID;
}
"#;

pub const SHADOW_SPHERE_FRAGMENT: &str = r#"#version 450 core
struct Sphere { vec4 centre_radius; uvec4 material; };
layout(std430, binding = 2) readonly buffer Spheres { Sphere spheres[]; };
uniform vec3 eye;
uniform mat3 camera_to_world;
uniform vec2 half_extent;
uniform bool ortho;
uniform float near_plane;
uniform float map_size;
uniform vec2 depth_range;
flat in int v_sphere;
layout(location = 0) out float stored;
void main() {
    vec4 s = spheres[v_sphere].centre_radius;
    float px = floor(gl_FragCoord.x) + 0.5;
    float py = (map_size - 1.0 - floor(gl_FragCoord.y)) + 0.5;
    vec2 q = vec2((2.0 * px / map_size - 1.0) * half_extent.x, (1.0 - 2.0 * py / map_size) * half_extent.y);
    vec3 o = ortho ? eye + camera_to_world * vec3(q, 0.0) : eye;
    vec3 d = ortho ? -camera_to_world[2] : camera_to_world * vec3(q, -1.0);
    vec3 u = normalize(d);
    vec3 f = o - s.xyz;
    float b = -dot(f, u);
    vec3 l = f + u * b;
    float dist = length(l);
    float disc = (s.w - dist) * (s.w + dist);
    if (!(disc >= 0.0)) discard;
    float h = sqrt(disc);
    float t = ortho ? b - h : (length(f) > s.w ? b - h : b + h);
    if (!ortho && !(t > 0.0)) discard;
    float view_depth = ortho ? t : t * dot(u, -camera_to_world[2]);
    gl_FragDepth = ortho ? clamp((depth_range.y - t) / (depth_range.y - depth_range.x), 0.0, 1.0) : clamp(near_plane / view_depth, 0.0, 1.0);
    stored = t;
}
"#;

/// A CSG object's bounding box, drawn as the spheres' cube is (both sides,
/// depth clamped), so that every pixel whose eye ray can meet it gets a
/// fragment.
pub const CSG_VERTEX: &str = r#"#version 450 core
layout(location = 0) in vec3 corner;
layout(std430, binding = 6) readonly buffer CsgObjects { vec4 csg_objects[]; };
uniform vec3 eye;
uniform mat3 world_to_camera;
uniform vec2 half_extent;
uniform vec2 ndc_shift;
uniform bool y_down;
uniform float near_plane;
uniform float far_plane;
uniform bool orthographic;
uniform int csg_object;
void main() {
    vec3 lo = csg_objects[3 * csg_object + 1].xyz;
    vec3 hi = csg_objects[3 * csg_object + 2].xyz;
    // A little larger than the bounds, so that the object is always inside.
    vec3 half_size = (hi - lo) * 0.5;
    vec3 grow = half_size * 0.01 + vec3(1e-4 * length(half_size) + 1e-6);
    vec3 position = (lo + hi) * 0.5 + corner * (half_size + grow);
    vec3 c = world_to_camera * (position - eye);
    float w = orthographic ? 1.0 : -c.z;
    float z = orthographic ? (far_plane + c.z) / (far_plane - near_plane) : near_plane * (far_plane - w) / (far_plane - near_plane);
    gl_Position = vec4(c.x / half_extent.x + ndc_shift.x * w, (c.y / half_extent.y + ndc_shift.y * w) * (y_down ? -1.0 : 1.0), z, w);
}
"#;

/// The CSG objects (`render::accel::csg` in GLSL): along the fragment's eye ray
/// each operand's inside intervals over the whole line (a sphere's two
/// roots; a closed mesh's crossings by the two-sided Möller-Trumbore test,
/// counted into intervals), combined by a stack machine running the tree's
/// postfix program (`csg_data`), each operation one sweep over the sorted
/// boundaries of its two operands; the first boundary of the result with
/// `0 < t < t_max` is the hit, shaded as `render::accel::csg::surface_hit` makes it
/// and written to `gl_FragDepth`. Lists are held in fixed arrays: an
/// operand with more than `MAX_IV` intervals or a mesh crossed more than
/// `MAX_CROSS` times along one ray loses the farthest.
pub fn csg_fragment(defines: &str) -> String {
    format!(
        "#version 450 core\n{defines}#define PER_SAMPLE 1\n{COMMON}{}",
        r#"
layout(std430, binding = 6) readonly buffer CsgObjects { vec4 csg_objects[]; };
layout(std430, binding = 7) readonly buffer CsgNodes { uvec4 csg_nodes[]; };
layout(std430, binding = 8) readonly buffer CsgSpheres { vec4 csg_spheres[]; };
layout(std430, binding = 9) readonly buffer CsgTriangles { vec4 csg_triangles[]; };
uniform int csg_object;
layout(location = 0) out vec4 colour;

#define MAX_IV 8
#define MAX_CROSS 16
#define MAX_STACK 4
#define MAX_EVENTS (4 * MAX_IV)

// A boundary: t, then the surface (sphere index, or triangle index and the
// weights of v1 and v2), its leaf and whether it is flipped.
struct Bd { float t; float b1; float b2; int surface; bool triangle; int leaf; bool flipped; };

Bd stack_enter[MAX_STACK][MAX_IV];
Bd stack_exit[MAX_STACK][MAX_IV];
int stack_count[MAX_STACK];

vec3 ray_origin;
vec3 ray_dir;

// A sphere's interval over the whole line, as `sphere_interval`.
bool sphere_interval(vec3 centre, float radius, out float t0, out float t1) {
    vec3 f = ray_origin - centre;
    float b = -dot(f, ray_dir);
    vec3 l = f + ray_dir * b;
    float dist = length(l);
    float disc = (radius - dist) * (radius + dist);
    if (!(disc >= 0.0)) return false;
    float h = sqrt(disc);
    t0 = b - h;
    t1 = b + h;
    return true;
}

// The two-sided Möller-Trumbore test over the whole line, as `crossing`.
bool crossing(vec3 v0, vec3 e1, vec3 e2, out float t, out float b1, out float b2, out bool entering) {
    vec3 p = cross(ray_dir, e2);
    float det = dot(e1, p);
    float epsilon = 8.0 * 1.1920929e-7 * length(e1) * length(e2);
    if (!(abs(det) > epsilon)) return false;
    float inv = 1.0 / det;
    vec3 s = ray_origin - v0;
    b1 = dot(s, p) * inv;
    if (!(b1 >= 0.0 && b1 <= 1.0)) return false;
    vec3 q = cross(s, e1);
    b2 = dot(ray_dir, q) * inv;
    if (b2 < 0.0 || b1 + b2 > 1.0) return false;
    t = dot(e2, q) * inv;
    entering = det > 0.0;
    return !isnan(t) && !isinf(t);
}

// Sort order of crossings: by t, entries first at equal t (stable).
bool crossing_before(Bd a, bool ea, Bd b, bool eb) {
    return a.t < b.t || (a.t == b.t && ea && !eb);
}

// Pushes a mesh leaf's intervals (`mesh_intervals`) on stack slot `s`.
void mesh_intervals(int s, int first, int end, int leaf, bool flipped) {
    Bd cross_at[MAX_CROSS];
    bool enters[MAX_CROSS];
    int n = 0;
    for (int i = first; i < end; i++) {
        vec3 v0 = csg_triangles[8 * i].xyz;
        vec3 v1 = csg_triangles[8 * i + 1].xyz;
        vec3 v2 = csg_triangles[8 * i + 2].xyz;
        float t, b1, b2;
        bool entering;
        if (!crossing(v0, v1 - v0, v2 - v0, t, b1, b2, entering)) continue;
        Bd b = Bd(t, b1, b2, i, true, leaf, flipped);
        // Insertion in sorted place (stable); past MAX_CROSS the farthest is lost.
        int k = min(n, MAX_CROSS - 1);
        if (n == MAX_CROSS && !crossing_before(b, entering, cross_at[k], enters[k])) continue;
        while (k > 0 && crossing_before(b, entering, cross_at[k - 1], enters[k - 1])) {
            cross_at[k] = cross_at[k - 1];
            enters[k] = enters[k - 1];
            k--;
        }
        cross_at[k] = b;
        enters[k] = entering;
        n = min(n + 1, MAX_CROSS);
    }
    int depth = 0;
    bool started = false;
    Bd start;
    int count = 0;
    for (int i = 0; i < n; i++) {
        if (enters[i]) {
            depth++;
            if (depth == 1) {
                start = cross_at[i];
                started = true;
            }
        } else {
            depth--;
            if (depth == 0 && started && count < MAX_IV) {
                stack_enter[s][count] = start;
                stack_exit[s][count] = cross_at[i];
                count++;
                started = false;
            } else if (depth == 0) {
                started = false;
            }
            depth = max(depth, 0);
        }
    }
    stack_count[s] = count;
}

bool op_inside(uint op, bool a, bool b) {
    if (op == 2u) return a || b;
    if (op == 3u) return a && b;
    return a && !b;
}

// Combines stack slots `s` (a) and `s + 1` (b) into `s` by one sweep
// (`combine`): events sorted by t, entries first, then a's first (stable).
void combine(uint op, int s) {
    Bd ev[MAX_EVENTS];
    bool ev_b[MAX_EVENTS];
    bool ev_enter[MAX_EVENTS];
    int n = 0;
    for (int side = 0; side < 2; side++) {
        int slot = s + side;
        for (int i = 0; i < stack_count[slot]; i++) {
            for (int e = 0; e < 2; e++) {
                Bd b = e == 0 ? stack_enter[slot][i] : stack_exit[slot][i];
                bool entering = e == 0;
                bool from_b = side == 1;
                int k = n;
                while (k > 0) {
                    Bd p = ev[k - 1];
                    bool before = b.t < p.t || (b.t == p.t && ((entering && !ev_enter[k - 1]) || (entering == ev_enter[k - 1] && !from_b && ev_b[k - 1])));
                    if (!before) break;
                    ev[k] = ev[k - 1];
                    ev_b[k] = ev_b[k - 1];
                    ev_enter[k] = ev_enter[k - 1];
                    k--;
                }
                ev[k] = b;
                ev_b[k] = from_b;
                ev_enter[k] = entering;
                n++;
            }
        }
    }
    int in_a = 0, in_b = 0;
    bool started = false;
    Bd start;
    int count = 0;
    for (int i = 0; i < n; i++) {
        bool was = op_inside(op, in_a > 0, in_b > 0);
        int d = ev_enter[i] ? 1 : -1;
        if (ev_b[i]) in_b += d; else in_a += d;
        bool now = op_inside(op, in_a > 0, in_b > 0);
        if (!was && now) {
            start = ev[i];
            started = true;
        } else if (was && !now) {
            if (started && count < MAX_IV) {
                stack_enter[s][count] = start;
                stack_exit[s][count] = ev[i];
                count++;
            }
            started = false;
        }
    }
    stack_count[s] = count;
}

void main() {
    vec3 d = camera_dir();
    ray_dir = normalize(camera_to_world * d);
    ray_origin = eye + camera_to_world * ray_start();
    float t_max = (far_plane - near_plane) * length(d);
    uvec4 header = floatBitsToUint(csg_objects[3 * csg_object]);
    int first = int(header.x), count = int(header.y);
    int top = 0;
    int leaf = 0;
    for (int i = first; i < first + count; i++) {
        uvec4 node = csg_nodes[i];
        bool flipped = node.w != 0u;
        if (node.x == 0u) {
            if (top >= MAX_STACK) discard;
            vec4 s = csg_spheres[2 * node.y];
            float t0, t1;
            if (sphere_interval(s.xyz, s.w, t0, t1)) {
                stack_enter[top][0] = Bd(t0, 0.0, 0.0, int(node.y), false, leaf, flipped);
                stack_exit[top][0] = Bd(t1, 0.0, 0.0, int(node.y), false, leaf, flipped);
                stack_count[top] = 1;
            } else {
                stack_count[top] = 0;
            }
            top++;
            leaf++;
        } else if (node.x == 1u) {
            if (top >= MAX_STACK) discard;
            mesh_intervals(top, int(node.y), int(node.z), leaf, flipped);
            top++;
            leaf++;
        } else {
            if (top < 2) discard;
            combine(node.x, top - 2);
            top--;
        }
    }
    if (top != 1) discard;
    // first_boundary, for rays that start outside.
    bool found = false;
    Bd hit;
    for (int i = 0; i < stack_count[0]; i++) {
        Bd e = stack_enter[0][i];
        if (e.t > 0.0) {
            if (e.t < t_max) {
                hit = e;
                found = true;
            }
            break;
        }
    }
    if (!found) discard;
    // surface_hit.
    vec3 p;
    vec3 outward;
    vec3 shading;
    vec2 uv;
    vec3 bary = vec3(0.0);
    uint m;
    if (!hit.triangle) {
        vec4 s = csg_spheres[2 * hit.surface];
        m = floatBitsToUint(csg_spheres[2 * hit.surface + 1].x);
        p = ray_origin + ray_dir * hit.t;
        vec3 o = (p - s.xyz) / s.w;
        float lo = length(o);
        outward = lo > 0.0 && !isinf(lo) ? o / lo : vec3(0.0, 1.0, 0.0);
        uv = vec2(0.5 + precise_atan2(outward.z, outward.x) * -0.5 * (1.0 / PI), 0.5 + precise_asin(clamp(outward.y, -1.0, 1.0)) * (1.0 / PI));
    } else {
        int i = hit.surface;
        vec3 v0 = csg_triangles[8 * i].xyz;
        vec3 v1 = csg_triangles[8 * i + 1].xyz;
        vec3 v2 = csg_triangles[8 * i + 2].xyz;
        m = floatBitsToUint(csg_triangles[8 * i].w);
        vec3 w = vec3(1.0 - hit.b1 - hit.b2, hit.b1, hit.b2);
        p = v0 * w.x + v1 * w.y + v2 * w.z;
        outward = normalize(cross(v1 - v0, v2 - v0));
        vec3 ns = csg_triangles[8 * i + 3].xyz * w.x + csg_triangles[8 * i + 4].xyz * w.y + csg_triangles[8 * i + 5].xyz * w.z;
        float ls = length(ns);
        shading = ls > 0.0 && !isinf(ls) ? ns / ls : outward;
        vec4 uv01 = csg_triangles[8 * i + 6];
        uv = uv01.xy * w.x + uv01.zw * w.y + csg_triangles[8 * i + 7].xy * w.z;
        bary = w;
    }
    if (!hit.triangle) shading = outward;
    float sign = hit.flipped ? -1.0 : 1.0;
    vec3 g = outward * sign;
    vec3 n = shading * sign;
    bool back = dot(g, ray_dir) > 0.0;
    if (back) {
        g = -g;
        n = -n;
    }
#ifdef VIEWS
    write_surface(p, n, back, g, bary, uv, 2u, uint(csg_object));
    out_id.z = m;
#endif
    float depth = dot(p - eye, -camera_to_world[2]);
    gl_FragDepth = stored_depth(depth);
    // CSG hits carry no footprint: the finest texture level.
    colour = vec4(shade(p, n, vec3(0.0), g, -ray_dir, m, albedo_at(m, uv, vec2(0.0), vec2(0.0))) + emitted(m, back), 1.0);
}
"#
    )
}
