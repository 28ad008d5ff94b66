"""pidcore.model"""
