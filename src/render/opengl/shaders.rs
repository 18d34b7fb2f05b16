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

vec3 shade(vec3 p, vec3 n, vec3 w_o, uint m) {
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
        vec3 f = albedo * (1.0 / PI);
        if (glossy != vec3(0.0)) {
            vec3 w_h = normalize_or_zero(w_i + w_o);
            float c = max(dot(n, w_h), 0.0);
            if (s * (1.0 - c) < 20.7) {
                f += glossy * ((s + 8.0) / (8.0 * PI) * pow(c, s));
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

pub fn triangle_fragment() -> String {
    format!(
        "#version 450 core\n{COMMON}{}",
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
    colour = vec4(shade(v_position, n, -dir, v_material), 1.0);
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

pub fn sphere_fragment() -> String {
    format!(
        "#version 450 core\n{COMMON}{}",
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
    colour = vec4(shade(p, n, -dir, m), 1.0);
}
"#
    )
}
