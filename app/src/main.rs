fn main() -> anyhow::Result<()> {
    sylva_app::cli::main()
}
