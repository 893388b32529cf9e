// Readers of packed tables (tables/mod.rs). The includer defines
// `fn table_word(at: u32) -> u32`: the word `at` of the buffer the tables are in.

fn table_u32(at: u32) -> u32 {
    return table_word(at);
}

fn table_f32(at: u32) -> f32 {
    return bitcast<f32>(table_word(at));
}

fn table_vec3(at: u32) -> vec3<f32> {
    return vec3<f32>(table_f32(at), table_f32(at + 1u), table_f32(at + 2u));
}

fn table_vec4(at: u32) -> vec4<f32> {
    return vec4<f32>(table_vec3(at), table_f32(at + 3u));
}
