//! The render adapter a build's videos and frames were drawn on (`build.json`'s
//! `render_adapter`). Pixels differ between adapters (GPU models, drivers, and for a CPU
//! rasterizer such as Mesa's lavapipe possibly the CPU's vector features), so a dataset's
//! model inputs are one set only when every shard names the same adapter.

use serde::{Deserialize, Serialize};

/// Environment variable of Mesa's llvmpipe/lavapipe that sets its SIMD vector width.
pub const LP_NATIVE_VECTOR_WIDTH: &str = "LP_NATIVE_VECTOR_WIDTH";

/// What identifies the adapter that rendered a build (from wgpu's `AdapterInfo`, plus the
/// CPU features a CPU rasterizer compiles its shaders for).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RenderAdapter {
    /// Adapter name, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)" or "NVIDIA H100".
    pub name: String,
    /// Graphics backend, e.g. "vulkan".
    pub backend: String,
    /// "cpu", "discrete_gpu", "integrated_gpu", "virtual_gpu" or "other".
    pub device_type: String,
    /// Driver name, e.g. "llvmpipe".
    pub driver: String,
    /// Driver version text, e.g. "Mesa 22.3.6 (LLVM 15.0.6)".
    pub driver_info: String,
    /// For a CPU adapter: the CPU's vector features that the rasterizer's JIT may use
    /// (empty for a GPU).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub cpu_features: Vec<String>,
    /// For a CPU adapter: `LP_NATIVE_VECTOR_WIDTH` when it was set.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lp_native_vector_width: Option<String>,
}

impl RenderAdapter {
    /// One line naming the adapter, e.g. "llvmpipe (LLVM 15.0.6, 256 bits) [vulkan, cpu,
    /// llvmpipe Mesa 22.3.6; cpu avx,avx2,fma]".
    pub fn describe(&self) -> String {
        let mut s = format!(
            "{} [{}, {}, {} {}",
            self.name, self.backend, self.device_type, self.driver, self.driver_info
        );
        if !self.cpu_features.is_empty() {
            s += &format!("; cpu {}", self.cpu_features.join(","));
        }
        if let Some(w) = &self.lp_native_vector_width {
            s += &format!("; {LP_NATIVE_VECTOR_WIDTH}={w}");
        }
        s + "]"
    }
}

/// The vector features of this machine's CPU that a JIT rasterizer (llvmpipe) can use,
/// in a fixed order; empty on other architectures.
pub fn cpu_vector_features() -> Vec<String> {
    #[allow(unused_mut)]
    let mut out: Vec<&str> = Vec::new();
    #[cfg(target_arch = "x86_64")]
    {
        macro_rules! probe {
            ($($f:tt),*) => {
                $(if std::arch::is_x86_feature_detected!($f) { out.push($f); })*
            };
        }
        probe!(
            "sse4.1", "sse4.2", "avx", "avx2", "fma", "f16c", "avx512f", "avx512bw", "avx512vl",
            "avx512dq"
        );
    }
    #[cfg(target_arch = "aarch64")]
    {
        if std::arch::is_aarch64_feature_detected!("neon") {
            out.push("neon");
        }
    }
    out.into_iter().map(String::from).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn describe_names_driver_and_cpu_features() {
        let a = RenderAdapter {
            name: "llvmpipe (LLVM 15.0.6, 256 bits)".into(),
            backend: "vulkan".into(),
            device_type: "cpu".into(),
            driver: "llvmpipe".into(),
            driver_info: "Mesa 22.3.6".into(),
            cpu_features: vec!["avx2".into()],
            lp_native_vector_width: Some("128".into()),
        };
        let d = a.describe();
        assert!(d.contains("llvmpipe (LLVM 15.0.6, 256 bits)"), "{d}");
        assert!(d.contains("Mesa 22.3.6") && d.contains("cpu avx2"), "{d}");
        assert!(d.contains("LP_NATIVE_VECTOR_WIDTH=128"), "{d}");
        let back: RenderAdapter =
            serde_json::from_str(&serde_json::to_string(&a).unwrap()).unwrap();
        assert_eq!(back, a);
    }
}
