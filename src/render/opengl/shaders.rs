//! The GLSL programs: `shade()` of the CPU renderers (`render::lighting`)
//! written again for the fragment shader, a triangle program and an exact
//! sphere program (a bounding cube whose fragments intersect the sphere).

/// What both fragment shaders share: the eye ray through this fragment's
/// sample position, computed as `CameraView::eye_ray` computes it, and the
/// shading of CGPP listing 15.19 (point lights `power / (4 pi d^2)`,
/// directional lights, Lambertian `k_L / pi` plus normalized Blinn-Phong,
/// the lobe skipped where `s (1 - c) >= 20.7`, ambient `albedo * ambient`).
const COMMON: &str = r#"
uniform vec3 eye;
uniform mat3 camera_to_world;
uniform vec2 half_extent;
uniform vec2 image_size;
uniform vec2 sample_offset;
uniform float near_plane;
uniform float far_plane;
uniform vec3 ambient;
uniform int light_count;

// Per material: (k_L, 0), (k_G, sharpness).
layout(std430, binding = 0) readonly buffer Materials { vec4 materials[]; };
// Per light: (position or direction, 0 = point | 1 = directional), (power or irradiance, 0).
layout(std430, binding = 1) readonly buffer Lights { vec4 lights[]; };

const float PI = 3.14159265358979323846;

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

// Camera-space direction (z = -1) through this fragment's sample, pixel rows top-down.
vec3 camera_dir() {
    float px = floor(gl_FragCoord.x) + sample_offset.x;
    float py = (image_size.y - 1.0 - floor(gl_FragCoord.y)) + sample_offset.y;
    return vec3((2.0 * px / image_size.x - 1.0) * half_extent.x, (1.0 - 2.0 * py / image_size.y) * half_extent.y, -1.0);
}

vec3 normalize_or_zero(vec3 v) {
    float l = length(v);
    return l > 0.0 ? v / l : vec3(0.0);
}

vec3 shade(vec3 p, vec3 n, vec3 g, vec3 w_o, uint m) {
    vec3 albedo = materials[2u * m].xyz;
    vec3 glossy = materials[2u * m + 1u].xyz;
    float s = materials[2u * m + 1u].w;
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
        vec3 f = albedo * (1.0 / PI);
        if (glossy != vec3(0.0)) {
            vec3 w_h = normalize_or_zero(w_i + w_o);
            float c = max(dot(n, w_h), 0.0);
            if (s * (1.0 - c) < 20.7) {
                f += glossy * ((s + 2.0) * (s + 4.0) / (8.0 * PI * (exp2(max(-0.5 * s, -126.0)) + s)) * pow(c, s));
            }
        }
        l_o += (incident * f) * cos_theta;
    }
    return l_o;
}
"#;

pub const TRIANGLE_VERTEX: &str = r#"#version 450 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec3 face_normal;
layout(location = 3) in uint material;
uniform vec3 eye;
uniform mat3 world_to_camera;
uniform vec2 half_extent;
// Moves the image so that GL's pixel centre samples this pass's sample position (NDC units).
uniform vec2 ndc_shift;
uniform float near_plane;
uniform float far_plane;
out vec3 v_position;
out vec3 v_normal;
flat out vec3 v_face_normal;
flat out uint v_material;
void main() {
    vec3 c = world_to_camera * (position - eye);
    float w = -c.z;
    // Reversed depth with glClipControl(ZERO_TO_ONE): near -> 1, far -> 0.
    float z = near_plane * (far_plane - w) / (far_plane - near_plane);
    gl_Position = vec4(c.x / half_extent.x + ndc_shift.x * w, c.y / half_extent.y + ndc_shift.y * w, z, w);
    v_position = position;
    v_normal = normal;
    v_face_normal = face_normal;
    v_material = material;
}
"#;

pub fn triangle_fragment(defines: &str) -> String {
    format!(
        "#version 450 core\n{defines}{COMMON}{}",
        r#"
uniform bool flat_shading;
in vec3 v_position;
in vec3 v_normal;
flat in vec3 v_face_normal;
flat in uint v_material;
layout(location = 0) out vec4 colour;
void main() {
    vec3 dir = normalize(camera_to_world * camera_dir());
    vec3 g = v_face_normal;
    float l = length(v_normal);
    vec3 n = l > 0.0 ? v_normal / l : g;
    if (dot(g, dir) > 0.0) {
        g = -g;
        n = -n;
    }
    if (flat_shading) n = g;
    colour = vec4(shade(v_position, n, g, -dir, v_material), 1.0);
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
uniform float near_plane;
uniform float far_plane;
flat out int v_sphere;
void main() {
    vec4 s = spheres[gl_InstanceID].centre_radius;
    // Slightly larger than the sphere, so its silhouette is always inside.
    vec3 position = s.xyz + corner * (s.w * 1.01);
    vec3 c = world_to_camera * (position - eye);
    float w = -c.z;
    float z = near_plane * (far_plane - w) / (far_plane - near_plane);
    gl_Position = vec4(c.x / half_extent.x + ndc_shift.x * w, c.y / half_extent.y + ndc_shift.y * w, z, w);
    v_sphere = gl_InstanceID;
}
"#;

pub fn sphere_fragment(defines: &str) -> String {
    format!(
        "#version 450 core\n{defines}{COMMON}{}",
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
    vec3 origin = eye + camera_to_world * (d * near_plane);
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
    vec3 n = (p - s.xyz) / s.w;
    if (dot(n, dir) > 0.0) n = -n;
    float w = dot(p - eye, -camera_to_world[2]);
    gl_FragDepth = clamp(near_plane * (far_plane - w) / ((far_plane - near_plane) * w), 0.0, 1.0);
    colour = vec4(shade(p, n, n, -dir, m), 1.0);
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
